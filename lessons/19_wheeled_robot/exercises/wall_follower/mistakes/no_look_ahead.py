"""Mistake: one ray to the right steers; nothing looks ahead, so a wall in front is not seen."""

import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import LaserScan

TARGET = 0.4  # m from the wall on the right
CRUISE = 0.2  # m/s


class WallFollower(Node):
    def __init__(self):
        super().__init__("wall_follower")
        self.publisher = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_subscription(LaserScan, "/scan", self.on_scan, 10)

    def on_scan(self, scan):
        right = scan.ranges[90]  # the ray at -90 degrees: straight to the right
        msg = Twist()
        msg.linear.x = CRUISE
        msg.angular.z = max(-1.2, min(1.2, 2.5 * (TARGET - right)))
        self.publisher.publish(msg)


def main():
    rclpy.init()
    node = WallFollower()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
