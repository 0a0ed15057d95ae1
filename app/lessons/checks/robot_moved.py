"""Check ``robot_moved``: the simulated robot (its ground truth) is far enough from a point.

``at_least`` is the distance at real time. The world moves the robot in simulated
time: when the computer ran it slower while the robot drove (0.4x under load), the
same commands drove it that share as far, and that share is asked (see _sim_drive).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from app.lessons.checks._sim_drive import newest_drive_of
from app.lessons.checks._sim_topics import ODOM_TYPE, TRUTH, pose_of
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "robot_moved",
    required="at_least",
    optional="x y",
    words="the simulated robot, where /ground_truth/odom says it really is, is at least so "
    "many metres from a point of the world (its start, the origin, unless given); when the "
    "computer ran the world slower than real time during the drive, that share of it",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    newest = rt.tap(TRUTH, ODOM_TYPE).message()
    if newest is None:
        if not rt.publishers(TRUTH):
            return CheckResult(FAIL, f"no publisher on {TRUTH}: is the simulation running?")
        return CheckResult(WAITING, f"waiting for a message on {TRUTH}")
    pose = pose_of(newest[1])
    x, y = float(c.get("x", 0.0)), float(c.get("y", 0.0))
    distance = math.dist((pose.x, pose.y), (x, y))
    text = f"the robot is at ({pose.x:.2f}, {pose.y:.2f}), {distance:.2f} m from ({x:g}, {y:g})"
    needed = float(c["at_least"])
    drive = newest_drive_of(rt)
    if drive is not None and drive.slower_words():
        needed *= drive.share
        text += f"; {drive.slower_words()}: {needed:.2f} m of the {c['at_least']:g} m is enough"
    if distance >= needed:
        return CheckResult(PASS, text)
    return CheckResult(WAITING, f"{text}; {needed:.2f} m needed")
