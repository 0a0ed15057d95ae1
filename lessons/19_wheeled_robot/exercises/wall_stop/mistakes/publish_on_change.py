"""Mistake: a command only when the decision changes; the base stops 0.5 s after the last."""

import math

import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import LaserScan

STOP_DISTANCE = 0.5  # m between the scanner and the wall when the robot stands
CRUISE = 0.25  # m/s while the way is clear
HALF_CONE = math.radians(10.0)


class WallStopper(Node):
    def __init__(self):
        super().__init__("wall_stopper")
        self.publisher = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_subscription(LaserScan, "/scan", self.on_scan, 10)
        self.moving = None  # the last decision sent

    def distance_ahead(self, scan):
        """The smallest range within a few degrees of straight ahead (m)."""
        nearest = math.inf
        for i, distance in enumerate(scan.ranges):
            angle = scan.angle_min + i * scan.angle_increment
            if abs(angle) > HALF_CONE or math.isnan(distance):
                continue
            if distance == -math.inf:  # closer than the scanner can measure
                distance = scan.range_min
            nearest = min(nearest, distance)
        return nearest

    def on_scan(self, scan):
        moving = self.distance_ahead(scan) > STOP_DISTANCE
        if moving == self.moving:
            return  # nothing new to say
        self.moving = moving
        msg = Twist()
        msg.linear.x = CRUISE if moving else 0.0
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
