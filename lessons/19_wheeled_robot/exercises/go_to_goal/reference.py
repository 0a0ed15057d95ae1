"""Reference: turn towards the goal, drive there, then turn to the goal's heading (from /odom)."""

import math

import rclpy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

ARRIVED = 0.02  # m: close enough to the goal's position
LEFT = 0.12  # m: further than this from the goal after arriving: drive again
FACING = 0.3  # rad: turn on the spot until the goal is this close to straight ahead
ALIGNED = 0.02  # rad: close enough to the goal's heading
MAX_TURN = 0.5  # rad/s: turning faster, the wheels slip and odometry loses the heading


def yaw_of(q):
    """The heading (rad) of a quaternion: its turn about z."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def wrap(angle):
    return math.atan2(math.sin(angle), math.cos(angle))


def clip(value, limit):
    return max(-limit, min(limit, value))


class GoToGoal(Node):
    def __init__(self):
        super().__init__("go_to_goal")
        self.declare_parameter("goal_x", 0.0)
        self.declare_parameter("goal_y", 0.0)
        self.declare_parameter("goal_yaw", 0.0)
        self.pose = None
        self.arrived = False
        self.goal = None
        self.publisher = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_subscription(Odometry, "/odom", self.on_odom, 10)
        self.create_timer(0.05, self.on_timer)

    def on_odom(self, msg):
        p = msg.pose.pose
        self.pose = (p.position.x, p.position.y, yaw_of(p.orientation))

    def on_timer(self):
        if self.pose is None:
            return
        goal = tuple(self.get_parameter(n).value for n in ("goal_x", "goal_y", "goal_yaw"))
        if goal != self.goal:  # a new goal: drive again
            self.goal, self.arrived = goal, False
        x, y, yaw = self.pose
        dx, dy = goal[0] - x, goal[1] - y
        distance = math.hypot(dx, dy)
        if self.arrived and distance > LEFT or not self.arrived and distance > ARRIVED:
            self.arrived = False
        else:
            self.arrived = True
        msg = Twist()
        if not self.arrived:
            turn = wrap(math.atan2(dy, dx) - yaw)
            msg.angular.z = clip(2.0 * turn, MAX_TURN)
            if abs(turn) < FACING:
                msg.linear.x = min(0.3, 0.8 * distance)
        else:
            turn = wrap(goal[2] - yaw)
            if abs(turn) > ALIGNED:
                msg.angular.z = math.copysign(max(0.1, min(MAX_TURN, 1.5 * abs(turn))), turn)
        self.publisher.publish(msg)


def main():
    rclpy.init()
    node = GoToGoal()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
