"""Check ``localized``: the localization's newest pose agrees with where the robot really is.

A localization node (amcl) publishes where it believes the robot is on the
map, ``/amcl_pose`` (geometry_msgs/PoseWithCovarianceStamped, latched). The
simulator knows the truth (``/ground_truth/odom``, in the world frame, which
is the office map's frame). The check takes the ground truth stamped at the
estimate's instant and passes when the two are within ``within`` metres
(and ``degrees``, if given).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from app.lessons.checks._sim_topics import ODOM_TYPE, TRUTH, pose_of, seconds, truth_at, yaw_of
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

ESTIMATE, ESTIMATE_TYPE = "/amcl_pose", "geometry_msgs/msg/PoseWithCovarianceStamped"


@register_check(
    "localized",
    required="within",
    optional="degrees",
    words="the newest /amcl_pose is within `within` metres (and `degrees`, if given) of where "
    "/ground_truth/odom says the robot was at that instant",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    newest = rt.tap(ESTIMATE, ESTIMATE_TYPE, history=True).message()
    if newest is None:
        if not rt.publishers(ESTIMATE):
            return CheckResult(FAIL, f"no publisher on {ESTIMATE}: is amcl running and active?")
        return CheckResult(WAITING, f"waiting for {ESTIMATE}: amcl needs an initial pose")
    estimate = newest[1]
    stamp = seconds(estimate.header.stamp)
    truth = truth_at(rt, stamp, within=0.2)
    if truth is None and stamp == 0.0:  # from an /initialpose sent without a stamp: now
        newest = rt.tap(TRUTH, ODOM_TYPE).message()
        truth = pose_of(newest[1]) if newest is not None else None
    if truth is None:
        if not rt.publishers(TRUTH):
            return CheckResult(FAIL, f"no publisher on {TRUTH}: is the simulation running?")
        return CheckResult(WAITING, f"no {TRUTH} of the estimate's instant yet: drive a little")
    p = estimate.pose.pose
    off = math.hypot(p.position.x - truth.x, p.position.y - truth.y)
    turn = abs(math.remainder(yaw_of(p.orientation) - truth.yaw, math.tau))
    text = (
        f"amcl puts the robot at ({p.position.x:.2f}, {p.position.y:.2f}), the simulator at "
        f"({truth.x:.2f}, {truth.y:.2f}): {off:.2f} m and {math.degrees(turn):.0f}° apart"
    )
    limit_deg = c.get("degrees")
    if off <= float(c["within"]) and (limit_deg is None or math.degrees(turn) <= limit_deg):
        return CheckResult(PASS, text)
    return CheckResult(WAITING, f"{text}; drive a little so that amcl updates")
