"""Exercise: publish "ready" once, in a way late subscribers still receive it."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


class StatusAnnouncer(Node):
    def __init__(self):
        super().__init__("status_announcer")
        # TODO 1: make a QoS profile that keeps the last message for late joiners.
        # TODO 2: create a publisher of String on "robot_status" with that profile.
        # TODO 3: publish String(data="ready") once, and log that you did.


def main():
    rclpy.init()
    node = StatusAnnouncer()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
