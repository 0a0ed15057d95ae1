"""A plausible mistake: print() instead of the logger, so nothing reaches /rosout."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

PERIOD_SEC = 0.5  # 2 Hz


class Heartbeat(Node):
    def __init__(self):
        super().__init__("heartbeat")
        self.count = 0
        self.timer = self.create_timer(PERIOD_SEC, self.on_timer)

    def on_timer(self):
        self.count += 1
        print(f"beat {self.count}")


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
