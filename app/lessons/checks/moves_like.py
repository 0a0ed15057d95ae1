"""Check ``moves_like``: one pose topic moves with the velocities of another, which is not
still.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "moves_like",
    required="topic type like",
    words="one pose topic moves with the velocities of another, which is not still",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    """``topic``'s newest pose moves with the velocities of ``like``'s, and is not still."""
    follower, leader = rt.tap(c["topic"], c["type"]), rt.tap(c["like"], c["type"])
    for tap in (follower, leader):
        if not rt.publishers(tap.topic):
            return CheckResult(FAIL, f"no publisher on {tap.topic}")
    newest_follower, newest_leader = follower.message(), leader.message()
    if newest_follower is None or newest_leader is None:
        return CheckResult(WAITING, f"waiting for poses on {c['topic']} and {c['like']}")
    f, lead = newest_follower[1], newest_leader[1]
    speeds = f"{lead.linear_velocity:.2f} m/s, {lead.angular_velocity:.2f} rad/s"
    if abs(lead.linear_velocity) + abs(lead.angular_velocity) < 0.01:
        return CheckResult(WAITING, f"{c['like']} is standing still; make it move")
    if math.isclose(f.linear_velocity, lead.linear_velocity, abs_tol=0.05) and math.isclose(
        f.angular_velocity, lead.angular_velocity, abs_tol=0.05
    ):
        return CheckResult(PASS, f"{c['topic']} moves like {c['like']} ({speeds})")
    return CheckResult(
        WAITING,
        f"{c['topic']} at {f.linear_velocity:.2f} m/s, {f.angular_velocity:.2f} rad/s; "
        f"{c['like']} at {speeds}",
    )
