"""Reference solution: publish 0, 1, 2, ... on /count at 5 Hz."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Int32

PERIOD_SEC = 0.2  # 5 Hz


class Counter(Node):
    def __init__(self):
        super().__init__("counter")
        self.count = 0
        self.publisher = self.create_publisher(Int32, "count", 10)
        self.timer = self.create_timer(PERIOD_SEC, self.on_timer)

    def on_timer(self):
        self.publisher.publish(Int32(data=self.count))
        self.count += 1


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
