"""Mistake: ranges[0] taken as straight ahead, as on a TurtleBot (here it looks backwards)."""

import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import LaserScan

STOP_DISTANCE = 0.5  # m between the scanner and the wall when the robot stands
CRUISE = 0.25  # m/s while the way is clear


class WallStopper(Node):
    def __init__(self):
        super().__init__("wall_stopper")
        self.publisher = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_subscription(LaserScan, "/scan", self.on_scan, 10)

    def distance_ahead(self, scan):
        """The first ray is straight ahead (true when angle_min is 0, not here)."""
        return scan.ranges[0]

    def on_scan(self, scan):
        ahead = self.distance_ahead(scan)
        msg = Twist()
        msg.linear.x = max(0.0, min(CRUISE, 0.8 * (ahead - STOP_DISTANCE)))
        self.get_logger().info(f"{ahead:.2f} m ahead", throttle_duration_sec=2.0)
        self.publisher.publish(msg)


def main():
    rclpy.init()
    node = WallStopper()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
