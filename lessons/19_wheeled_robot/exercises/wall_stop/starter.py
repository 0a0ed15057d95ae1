"""Exercise: drive towards the wall ahead and stop about 0.5 m before it, from /scan."""

import math

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
        """The smallest range within a few degrees of straight ahead (m)."""
        # TODO 1: ray i points at scan.angle_min + i * scan.angle_increment (rad).
        #         Return the smallest usable range of the rays near angle 0.
        return math.inf

    def on_scan(self, scan):
        ahead = self.distance_ahead(scan)
        msg = Twist()
        # TODO 2: forward at up to CRUISE m/s, slower near the wall, 0 at STOP_DISTANCE.
        #         Publish on every scan.
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
