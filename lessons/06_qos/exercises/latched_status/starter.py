"""Exercise: a status that late subscribers still receive, kept up to date."""

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
        self.subscription = self.create_subscription(String, "status_updates", self.on_update, 10)

    def on_update(self, msg):
        # TODO 4: publish the new status (msg.data) on "robot_status" too.
        pass


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
