"""Check ``robot_near``: the simulated robot really is near a point of the world."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from app.lessons.checks._sim_topics import ODOM_TYPE, TRUTH, pose_of
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "robot_near",
    required="x y within",
    words="the simulated robot, where /ground_truth/odom says it really is, is within "
    "`within` metres of the point (x, y) of the world",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    newest = rt.tap(TRUTH, ODOM_TYPE).message()
    if newest is None:
        if not rt.publishers(TRUTH):
            return CheckResult(FAIL, f"no publisher on {TRUTH}: is the simulation running?")
        return CheckResult(WAITING, f"waiting for a message on {TRUTH}")
    pose = pose_of(newest[1])
    x, y = float(c["x"]), float(c["y"])
    distance = math.dist((pose.x, pose.y), (x, y))
    text = f"the robot is at ({pose.x:.2f}, {pose.y:.2f}), {distance:.2f} m from ({x:g}, {y:g})"
    if distance <= float(c["within"]):
        return CheckResult(PASS, text)
    return CheckResult(WAITING, f"{text}; {c['within']:g} m or closer needed")
