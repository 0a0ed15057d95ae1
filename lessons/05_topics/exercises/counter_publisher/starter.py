"""Exercise: publish 0, 1, 2, ... on /count at 5 Hz."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Int32


class Counter(Node):
    def __init__(self):
        super().__init__("counter")
        self.count = 0
        # TODO 1: create a publisher of Int32 messages on the topic "count".
        # TODO 2: create a timer that calls self.on_timer five times a second.

    def on_timer(self):
        # TODO 3: publish self.count in an Int32 message, then add 1 to it.
        pass


def main():
    rclpy.init()
    node = Counter()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
