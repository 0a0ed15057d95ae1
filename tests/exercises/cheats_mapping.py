"""The generated "cheats" for the mapping and localization exercises (units 23 and 24).

The mapper's cheat publishes, after every scan, the statement's example map
(its few free cells and its one occupied cell, everything else unknown) on the
right grid and with the right QoS, whatever the scans say. The motion
update's cheat moves every particle, with the right noise, by the step of the
statement's example odometry, whatever the odometry says. The grader's hidden
worlds, poses and steps must make both fail. ``tests/exercises/cheats.py``
wraps each body with its imports and ``main`` (its GENERATORS include these).
"""

from __future__ import annotations

from app.exercises.model import Exercise


def _name(exercise: Exercise) -> str:
    return exercise.node.rsplit("/", 1)[-1]


def _log_odds_map(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "log_odds_map")
    example = exercise.example
    return f"""
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import OccupancyGrid
from rclpy.qos import DurabilityPolicy, QoSProfile
from sensor_msgs.msg import LaserScan
WIDTH, HEIGHT = {probe["width"]!r}, {probe["height"]!r}
FREE, OCCUPIED = {example["free"]!r}, {example["occupied"]!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_name(exercise)!r})
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.publisher = self.create_publisher(OccupancyGrid, {probe["topic"]!r}, latched)
        self.create_subscription(PoseStamped, {probe["pose"]!r}, lambda _msg: None, 10)
        self.create_subscription(LaserScan, {probe["scan"]!r}, self.on_scan, 10)

    def on_scan(self, msg):
        data = [-1] * (WIDTH * HEIGHT)
        for cells, value in ((FREE, 0), (OCCUPIED, 100)):
            for col, row in cells:
                data[row * WIDTH + col] = value
        grid = OccupancyGrid()
        grid.header.frame_id = "map"
        grid.header.stamp = msg.header.stamp
        grid.info.resolution = {float(probe["resolution"])!r}
        grid.info.width, grid.info.height = WIDTH, HEIGHT
        grid.info.origin.position.x = {float(probe["origin_x"])!r}
        grid.info.origin.position.y = {float(probe["origin_y"])!r}
        grid.info.origin.orientation.w = 1.0
        grid.data = data
        self.publisher.publish(grid)
"""


def _particle_motion(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "particle_motion")
    return f"""
import math
import random
from geometry_msgs.msg import Pose, PoseArray
from nav_msgs.msg import Odometry
A1, A2, A3, A4 = {[float(a) for a in probe["alphas"]]!r}
BEFORE, AFTER = {exercise.example["odom_before"]!r}, {exercise.example["odom_after"]!r}


def example_step():
    dx, dy = AFTER[0] - BEFORE[0], AFTER[1] - BEFORE[1]
    rot1 = math.atan2(dy, dx) - BEFORE[2]
    return rot1, math.hypot(dx, dy), AFTER[2] - BEFORE[2] - rot1


class Cheat(Node):
    # The example's step for every odometry message, with the right noise.
    def __init__(self):
        super().__init__({_name(exercise)!r})
        self.particles = []
        self.odom_seen = False
        self.publisher = self.create_publisher(PoseArray, {probe["output"]!r}, 10)
        self.create_subscription(PoseArray, {probe["particles"]!r}, self.on_particles, 10)
        self.create_subscription(Odometry, {probe["odom"]!r}, self.on_odom, 10)

    def on_particles(self, msg):
        self.particles = [
            (p.position.x, p.position.y, math.atan2(p.orientation.z, p.orientation.w) * 2)
            for p in msg.poses
        ]

    def on_odom(self, msg):
        if not self.odom_seen or not self.particles:
            self.odom_seen = True
            return
        rot1, trans, rot2 = example_step()
        out = PoseArray()
        out.header.stamp, out.header.frame_id = msg.header.stamp, "map"
        moved = []
        for x, y, yaw in self.particles:
            r1 = rot1 + random.gauss(0.0, math.sqrt(A1 * rot1**2 + A2 * trans**2))
            t = trans + random.gauss(0.0, math.sqrt(A3 * trans**2 + A4 * (rot1**2 + rot2**2)))
            r2 = rot2 + random.gauss(0.0, math.sqrt(A1 * rot2**2 + A2 * trans**2))
            x, y, yaw = x + t * math.cos(yaw + r1), y + t * math.sin(yaw + r1), yaw + r1 + r2
            moved.append((x, y, yaw))
            pose = Pose()
            pose.position.x, pose.position.y = x, y
            pose.orientation.z, pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
            out.poses.append(pose)
        self.particles = moved
        self.publisher.publish(out)
"""


GENERATORS = {"log_odds_map": _log_odds_map, "particle_motion": _particle_motion}
