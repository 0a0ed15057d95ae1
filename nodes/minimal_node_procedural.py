"""minimal_node_procedural: the minimal node again, without writing a class.

It does exactly what ``minimal_node`` does (log "Hello ROS2" five times a
second) but builds the node with ``rclpy.create_node(name)`` and uses a plain
function as the timer callback. That is fine for a quick experiment; as soon
as a node keeps state (counters, publishers, parameters) the class version is
easier to read and to extend, which is why ROS 2 code is usually written that
way.

ROS concepts shown
- ``rclpy.create_node(name)`` returns a ready ``Node`` object;
- any callable can be a callback: here a nested function that captures the
  node from the enclosing scope;
- the same init / spin / destroy / shutdown life cycle as every node:
  ``spin_node`` (nodes/common/run.py) runs it, ``minimal_node`` writes it out.
"""

import rclpy
from rclpy.node import Node

from nodes.common.run import spin_node

TIMER_PERIOD_SEC = 0.2  # 5 Hz


def make_node() -> Node:
    node = rclpy.create_node("minimal_node_procedural")

    def on_timer() -> None:
        node.get_logger().info("Hello ROS2")

    node.create_timer(TIMER_PERIOD_SEC, on_timer)
    return node


def main(args=None) -> None:
    spin_node(make_node, args)


if __name__ == "__main__":
    main()
