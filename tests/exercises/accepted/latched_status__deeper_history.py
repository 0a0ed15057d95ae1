"""Accepted, written differently: a reliable transient-local profile keeping ten statuses
(a late joiner gets them all, the newest last)."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

LATCHED = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=10,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)


class Announcer(Node):
    def __init__(self):
        super().__init__("status_announcer")
        self.status = self.create_publisher(String, "/robot_status", LATCHED)
        self.create_subscription(String, "/status_updates", self.status.publish, 10)
        self.status.publish(String(data="ready"))


def main():
    rclpy.init()
    node = Announcer()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
