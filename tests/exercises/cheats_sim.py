"""Generated "cheat" solutions for the simulation probes: they replay the statement's example.

Each exercise of the "Drive a robot" unit shows an example drive in its
statement (``example`` in exercise.toml). A learner could replay that drive
without looking at the world: these nodes do, as well as it can be done
(by odometry, starting over whenever the world is reset), and the grader's
random starts and goals must make them fail.

Each generator returns a node body (a ``class Cheat(Node)`` named as the
exercise's node), in the form ``tests/exercises/cheats.py`` wraps with its
imports and ``main``. To use them there::

    from tests.exercises.cheats_sim import GENERATORS as SIM_GENERATORS

    GENERATORS = {..., **SIM_GENERATORS}
"""

from __future__ import annotations

from app.exercises.model import Exercise

# Odometry helpers every cheat uses: the odom frame starts over at each reset of the world.
_ODOM = """
import math

from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def wrap(angle):
    return math.atan2(math.sin(angle), math.cos(angle))


def reset_seen(pose, before):
    # The odometry jumped back to its origin: the world was reset, the drive starts over.
    return before is not None and math.hypot(pose[0], pose[1]) < 0.01 < math.hypot(
        before[0] - pose[0], before[1] - pose[1]
    )
"""


def _node_name(exercise: Exercise) -> str:
    return exercise.node.rsplit("/", 1)[-1]


def _sim_wall_stop(exercise: Exercise) -> str:
    """Drive the example's distance (wall ahead minus the stop distance) by odometry, stop."""
    example = exercise.example
    distance = float(example["ahead"]) - float(example["stop"])
    return (
        _ODOM
        + f"""
DISTANCE = {distance!r}  # the example's wall was {example["ahead"]!r} m ahead
SPEED = {float(example["speed"])!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.publisher = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_subscription(Odometry, "/odom", self.on_odom, 10)

    def on_odom(self, msg):
        p = msg.pose.pose.position
        out = Twist()
        out.linear.x = SPEED if math.hypot(p.x, p.y) < DISTANCE else 0.0
        self.publisher.publish(out)
"""
    )


def _sim_wall_follow(exercise: Exercise) -> str:
    """The example's lap by odometry: its first leg, then legs along a room's sides, left turns."""
    example = exercise.example
    first = float(example["first_leg"])
    side = 4.0 - 2.0 * float(example["wall"])  # the room's inner size less the wall distance
    return (
        _ODOM
        + f"""
FIRST_LEG, LEG = {first!r}, {side!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.publisher = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_subscription(Odometry, "/odom", self.on_odom, 10)
        self.pose = None
        self.restart()

    def restart(self):
        self.leg, self.turning, self.mark = FIRST_LEG, False, None

    def on_odom(self, msg):
        p = msg.pose.pose
        pose = (p.position.x, p.position.y, yaw_of(p.orientation))
        if reset_seen(pose, self.pose):
            self.restart()
        self.pose = pose
        if self.mark is None:
            self.mark = pose
        out = Twist()
        if self.turning:
            if abs(wrap(pose[2] - self.mark[2])) < math.pi / 2:
                out.angular.z = 0.5
            else:
                self.turning, self.leg, self.mark = False, LEG, pose
        elif math.hypot(pose[0] - self.mark[0], pose[1] - self.mark[1]) < self.leg:
            out.linear.x = 0.2
        else:
            self.turning, self.mark = True, pose
        self.publisher.publish(out)
"""
    )


def _sim_go_to_goal(exercise: Exercise) -> str:
    """Drive to the example's goal by odometry (the goal parameters are accepted, not used)."""
    gx, gy, gyaw = (float(v) for v in exercise.example["goal"])
    return (
        _ODOM
        + f"""
GOAL = ({gx!r}, {gy!r}, {gyaw!r})


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        for name in ("goal_x", "goal_y", "goal_yaw"):
            self.declare_parameter(name, 0.0)
        self.publisher = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_subscription(Odometry, "/odom", self.on_odom, 10)

    def on_odom(self, msg):
        p = msg.pose.pose
        x, y, yaw = p.position.x, p.position.y, yaw_of(p.orientation)
        dx, dy = GOAL[0] - x, GOAL[1] - y
        out = Twist()
        if math.hypot(dx, dy) > 0.03:
            turn = wrap(math.atan2(dy, dx) - yaw)
            out.angular.z = max(-0.5, min(0.5, 2.0 * turn))
            if abs(turn) < 0.3:
                out.linear.x = min(0.3, 0.8 * math.hypot(dx, dy))
        elif abs(wrap(GOAL[2] - yaw)) > 0.03:
            out.angular.z = math.copysign(0.3, wrap(GOAL[2] - yaw))
        self.publisher.publish(out)
"""
    )


GENERATORS = {
    "sim_wall_stop": _sim_wall_stop,
    "sim_wall_follow": _sim_wall_follow,
    "sim_go_to_goal": _sim_go_to_goal,
}
