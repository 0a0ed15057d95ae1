"""minimal_node: the smallest useful ROS 2 node, written as a class.

Every ROS 2 Python program in this course grows from this skeleton:

1. ``rclpy.init()`` connects the process to ROS (it reads ``--ros-args``);
2. a class derived from ``rclpy.node.Node`` gets its name in
   ``super().__init__("minimal_node")`` and sets up everything it needs in its
   constructor, here one timer;
3. ``rclpy.spin(node)`` hands control to ROS, which calls our callbacks when
   there is work: here ``on_timer`` five times a second (a 0.2 s period);
4. on Ctrl+C (SIGINT) or SIGTERM the spin ends, the node is destroyed and ROS
   is shut down, in that order.

ROS concepts shown
- a node is an object; its timers, publishers and so on are attributes;
- ``create_timer(period_sec, callback)``;
- ``get_logger().info(...)``: a log line on the console and on /rosout.

The other nodes of the course hand steps 1, 3 and 4 to ``spin_node``
(nodes/common/run.py), which does exactly what ``main`` below spells out.
Compare it with ``minimal_node_procedural``, the same node without a class.
Try it: ``ros2 run tutorial_nodes minimal_node`` and ``ros2 node list``.
"""

import rclpy
from rclpy.node import Node

from nodes.common.run import init_ros, ros_started, stopped_quietly

TIMER_PERIOD_SEC = 0.2  # 5 Hz


class MinimalNode(Node):
    def __init__(self) -> None:
        super().__init__("minimal_node")
        self.timer = self.create_timer(TIMER_PERIOD_SEC, self.on_timer)

    def on_timer(self) -> None:
        self.get_logger().info("Hello ROS2")


def main(args=None) -> None:
    node = None
    try:
        with stopped_quietly():  # Ctrl+C (SIGINT) or SIGTERM, at any point: leave quietly
            init_ros(args)  # rclpy.init(args=args); rclpy's signal handlers come ...
            node = MinimalNode()
            ros_started()  # ... once the node is made (a stop during start-up is safe)
            rclpy.spin(node)
    finally:
        # Ctrl+C can arrive before the node exists: clean up only what was made.
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
