"""The robot's newest drive as the world ran it, and how fast simulated time ran meanwhile.

A drive such as ``ros2 topic pub -t 40 -r 10 /cmd_vel ...`` lasts 4 s of the
wall clock. sim_world moves the robot in simulated time: a computer that runs
the world at 0.4x of real time turns those 4 s into 1.6 s of simulated driving,
and the robot covers 40 % of the ground (measured under load: 0.38 m where 0.8 m
was commanded). So the drive checks ask for the share of the distance that the
simulated time allowed, and say so.

The watch keeps each /ground_truth/odom pose with the world's wall time (the
middleware's source timestamp: the world's own clock, whenever we hear it) beside
its stamp (simulation time). The drive is the newest stretch in which the robot
moved; its factor is simulated seconds over wall seconds across that stretch.
The math is a plain function (``newest_drive``), testable without ROS.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy

from app.lessons.checks._sim_speed import factor_text
from app.lessons.checks._sim_topics import TRUTH, Pose, pose_of, wrap
from app.ros.monitor import MessageInfo

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime

TRACK_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT)
TRACK_KEEP = 4000  # poses: over 2 min of simulated time at 30 Hz
MOVING = 0.02  # m/s (or rad/s) of simulated time: slower is standing still
JUMP = 3.0  # m/s: faster than the robot drives: a reset put it back (not a drive)
STILL_ENDS = 0.5  # s of simulated standstill that separate two drives
MIN_WALL = 0.5  # s: a shorter drive tells no factor
SLOWER = 0.95  # below this share of real time, the checks scale and say so


@dataclass(frozen=True)
class Drive:
    """The newest drive: where it began and ended, and simulated s per wall s meanwhile."""

    start: Pose
    end: Pose
    factor: float | None  # None: too short to tell

    @property
    def share(self) -> float:
        """The share of a real-time drive's distance the simulated time allowed (at most 1)."""
        return 1.0 if self.factor is None else max(0.0, min(1.0, self.factor))

    def slower_words(self) -> str:
        """What the learner is told when the world ran slower than real time, else ''."""
        if self.share >= SLOWER or self.factor is None:
            return ""
        return (
            f"the world ran at {factor_text(self.factor)} of real time while the robot "
            "drove (your computer could not keep up), so the same commands lasted "
            f"{self.share:.0%} as long in simulated time"
        )


def _moving(a: Pose, b: Pose) -> bool | None:
    """Whether the robot moved from ``a`` to ``b``; None: not a drive (a reset, time back)."""
    dt = b.t - a.t
    if dt <= 0:
        return None
    speed = math.dist((a.x, a.y), (b.x, b.y)) / dt
    if speed > JUMP:
        return None
    return speed > MOVING or abs(wrap(b.yaw - a.yaw)) / dt > MOVING


def newest_drive(track: Sequence[tuple[float, Pose]]) -> Drive | None:
    """The newest drive in a track of (the world's wall time, pose), oldest first: the
    stretch from where the robot began to move to its newest moving pose, standstills
    shorter than ``STILL_ENDS`` included. None when the track shows no motion."""
    end = None
    i = len(track) - 1
    while i > 0 and end is None:
        moved = _moving(track[i - 1][1], track[i][1])
        if moved is None:
            return None
        if moved:
            end = i
        i -= 1
    if end is None:
        return None
    start = end - 1
    i = start
    while i > 0:
        moved = _moving(track[i - 1][1], track[i][1])
        if moved is None or (not moved and track[start][1].t - track[i - 1][1].t > STILL_ENDS):
            break
        if moved:
            start = i - 1
        i -= 1
    (w0, p0), (w1, p1) = track[start], track[end]
    factor = (p1.t - p0.t) / (w1 - w0) if w1 - w0 >= MIN_WALL else None
    return Drive(p0, p1, factor)


class DriveWatch:
    """/ground_truth/odom poses, each with the world's wall time."""

    def __init__(self, node: Node) -> None:
        self.node = node
        self.lock = threading.Lock()
        self.track: deque[tuple[float, Pose]] = deque(maxlen=TRACK_KEEP)
        # Two parameters: rclpy passes the message info (a dict) as the second.
        self._subscription = node.create_subscription(Odometry, TRUTH, self._on_pose, TRACK_QOS)  # type: ignore[arg-type]

    def _on_pose(self, msg: Odometry, info: MessageInfo) -> None:
        stamp = info.get("source_timestamp") or 0
        sample = (stamp * 1e-9 if stamp > 0 else time.time(), pose_of(msg))
        with self.lock:
            self.track.append(sample)

    def drive(self) -> Drive | None:
        with self.lock:
            track = list(self.track)
        return newest_drive(track)

    def close(self) -> None:
        try:
            self.node.destroy_subscription(self._subscription)
        except Exception:  # the node is gone already: nothing left to free
            pass


def newest_drive_of(rt: LessonRuntime) -> Drive | None:
    """The newest drive the runtime's watch saw (it listens while drive checks read it)."""
    return rt.watch("sim_drive", DriveWatch).drive()
