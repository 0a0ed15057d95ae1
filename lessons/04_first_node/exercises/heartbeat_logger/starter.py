"""Exercise: a node that logs "beat N" twice a second."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node


class Heartbeat(Node):
    def __init__(self):
        super().__init__("heartbeat")
        self.count = 0
        # TODO 1: create a timer that calls self.on_timer twice a second.

    def on_timer(self):
        # TODO 2: count this beat and log "beat N" with the node's logger.
        pass


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
