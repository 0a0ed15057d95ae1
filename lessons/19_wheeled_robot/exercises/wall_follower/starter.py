"""Exercise: follow the wall on the robot's right at 0.4 m, turning left at corners."""

import math

import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import LaserScan

TARGET = 0.4  # m from the wall on the right
CRUISE = 0.2  # m/s
BLOCKED = 0.55  # m: something this close ahead means a corner: turn left


def nearest(scan, low, high):
    """(distance, bearing) of the closest return between two bearings (rad)."""
    best = (math.inf, 0.0)
    for i, distance in enumerate(scan.ranges):
        angle = scan.angle_min + i * scan.angle_increment
        if low <= angle <= high and not math.isnan(distance):
            distance = scan.range_min if distance == -math.inf else distance
            best = min(best, (distance, angle))
    return best


class WallFollower(Node):
    def __init__(self):
        super().__init__("wall_follower")
        self.publisher = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_subscription(LaserScan, "/scan", self.on_scan, 10)

    def on_scan(self, scan):
        ahead, _ = nearest(scan, math.radians(-25), math.radians(25))
        right, bearing = nearest(scan, math.radians(-135), math.radians(-45))
        msg = Twist()
        # TODO 1: something closer than BLOCKED ahead: turn left on the spot.
        # TODO 2: no wall near on the right: drive on, curving right to find one.
        # TODO 3: otherwise drive at CRUISE and steer with angular.z from how far the wall
        #         is (right against TARGET) and how the robot is turned (bearing against
        #         -90 degrees, straight to the right).
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
