"""What the simulation checks share: the world's topics, poses from Odometry, stamps.

sim_world publishes ``/odom`` (wheel odometry, frame ``odom``) and
``/ground_truth/odom`` (frame ``world``) in the same physics step, with the
same stamp, so the checks pair them by stamp. Stamps are simulation time.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import TYPE_CHECKING

from app.lessons.checks._world_map import WorldMap, load_world_map
from app.ros import rotations
from app.ros.planar import Pose

if TYPE_CHECKING:
    from builtin_interfaces.msg import Time
    from geometry_msgs.msg import Quaternion
    from nav_msgs.msg import Odometry

    from app.lessons.runtime import LessonRuntime

ODOM_TYPE = "nav_msgs/msg/Odometry"
TRUTH = "/ground_truth/odom"
ODOM = "/odom"
CLOCK = "/clock"
SIM_NODE = "/sim_world"
WALL_CLOCK_SECONDS = 1e8  # a stamp beyond this (1973) is wall-clock time, not simulation time


def seconds(stamp: Time) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def yaw_of(q: Quaternion) -> float:
    """Yaw of a geometry_msgs Quaternion."""
    return rotations.yaw_of(q.x, q.y, q.z, q.w)


def wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def pose_of(msg: Odometry) -> Pose:
    """The planar pose of a nav_msgs/Odometry message."""
    p = msg.pose.pose
    return Pose(seconds(msg.header.stamp), p.position.x, p.position.y, yaw_of(p.orientation))


def relative(start: tuple[float, float, float], pose: Pose) -> Pose:
    """``pose`` (world frame) seen from ``start`` (x, y, yaw): what odometry should say."""
    sx, sy, syaw = start
    dx, dy = pose.x - sx, pose.y - sy
    c, s = math.cos(syaw), math.sin(syaw)
    return Pose(pose.t, c * dx + s * dy, -s * dx + c * dy, wrap(pose.yaw - syaw))


def truth_at(rt: LessonRuntime, stamp: float, within: float = 0.02) -> Pose | None:
    """The ground-truth pose stamped closest to ``stamp`` (None if none within ``within`` s)."""
    best: Pose | None = None
    for _, msg in rt.tap(TRUTH, ODOM_TYPE).newest():
        pose = pose_of(msg)
        if best is None or abs(pose.t - stamp) < abs(best.t - stamp):
            best = pose
        if pose.t < stamp - within:
            break
    return best if best is not None and abs(best.t - stamp) <= within else None


@lru_cache(maxsize=8)
def world_map(world: str) -> WorldMap:
    """A world's floor plan, read once (its file does not change while a lesson runs)."""
    return load_world_map(world)


def bearing_words(angle: float) -> str:
    """Where a bearing points, for a learner: ahead, to the left, behind, to the right."""
    degrees = math.degrees(wrap(angle))
    if abs(degrees) <= 30:
        where = "ahead"
    elif abs(degrees) >= 150:
        where = "behind"
    else:
        where = "to the left" if degrees > 0 else "to the right"
    return f"{degrees:+.0f} deg, {where}"
