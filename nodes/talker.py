"""talker: publish "Hello World: N" on /chatter twice a second.

ROS concepts shown
- a node is a class that inherits from ``rclpy.node.Node``;
- ``create_publisher(type, topic, queue_size)`` makes a publisher; the queue
  size (10) is how many outgoing messages may wait if the network is slow;
- ``create_timer(period, callback)`` calls a method periodically while the
  node spins;
- ``get_logger().info`` prints a log line that also goes to /rosout.

Try it: ``ros2 run tutorial_nodes talker`` and, in another terminal,
``ros2 run tutorial_nodes listener``.
"""

from rclpy.node import Node
from std_msgs.msg import String

from nodes.common.run import spin_node


class Talker(Node):
    def __init__(self) -> None:
        super().__init__("talker")
        self.count = 0
        self.publisher = self.create_publisher(String, "chatter", 10)
        self.timer = self.create_timer(0.5, self.on_timer)

    def on_timer(self) -> None:
        msg = String(data=f"Hello World: {self.count}")
        self.publisher.publish(msg)
        self.get_logger().info(f'Publishing: "{msg.data}"')
        self.count += 1


def main(args=None) -> None:
    spin_node(Talker, args)


if __name__ == "__main__":
    main()
