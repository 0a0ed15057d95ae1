"""A plausible mistake: the timer period is 0.1 s, so it beats ten times a second."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

PERIOD_SEC = 0.1


class Heartbeat(Node):
    def __init__(self):
        super().__init__("heartbeat")
        self.count = 0
        self.timer = self.create_timer(PERIOD_SEC, self.on_timer)

    def on_timer(self):
        self.count += 1
        self.get_logger().info(f"beat {self.count}")


def main():
    rclpy.init()
    node = Heartbeat()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
