"""Reference: keep the nearest point on the right abeam and 0.4 m away; turn left at a wall."""

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
        if ahead < BLOCKED:
            msg.angular.z = 1.0  # a wall in front: turn left on the spot
        elif right > 2.0 * TARGET + 0.4:
            msg.linear.x, msg.angular.z = CRUISE, -0.6  # lost the wall: curve right to find it
        else:
            too_close = TARGET - right  # > 0: turn left, away from the wall
            turned_in = bearing + math.pi / 2  # > 0: heading towards the wall
            msg.linear.x = CRUISE
            msg.angular.z = max(-1.2, min(1.2, 2.5 * too_close + 1.5 * turned_in))
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
