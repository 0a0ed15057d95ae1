"""listener: print every message that arrives on /chatter.

ROS concepts shown
- ``create_subscription(type, topic, callback, queue_size)``: ROS calls the
  callback with each message while the node spins;
- the same program can run twice under different names with a remap:
  ``--ros-args -r __node:=listener2`` (the catalog's ``listener2``).
"""

from rclpy.node import Node
from std_msgs.msg import String

from nodes.common.run import spin_node


class Listener(Node):
    def __init__(self) -> None:
        super().__init__("listener")
        self.subscription = self.create_subscription(String, "chatter", self.on_chatter, 10)

    def on_chatter(self, msg: String) -> None:
        self.get_logger().info(f'I heard: "{msg.data}"')


def main(args=None) -> None:
    spin_node(Listener, args)


if __name__ == "__main__":
    main()
