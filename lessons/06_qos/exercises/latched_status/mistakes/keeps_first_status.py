"""A plausible mistake: updates are logged, but the status kept for late joiners stays 'ready'."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile
from std_msgs.msg import String


class StatusAnnouncer(Node):
    def __init__(self):
        super().__init__("status_announcer")
        # Transient local: the publisher keeps its last `depth` messages and hands
        # them to every subscriber that joins later (and asks for them).
        qos = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.publisher = self.create_publisher(String, "robot_status", qos)
        self.publisher.publish(String(data="ready"))
        self.get_logger().info("status published: ready")
        self.subscription = self.create_subscription(String, "status_updates", self.on_update, 10)

    def on_update(self, msg):
        self.get_logger().info(f"status published: {msg.data}")


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
