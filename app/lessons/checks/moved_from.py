"""Check ``moved_from``: the newest pose on the topic is far enough from a start point."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "moved_from",
    required="topic type x y at_least",
    words="the newest pose on the topic is far enough from a start point",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    """The newest pose (any message with x and y) is far enough from a start point."""
    tap = rt.tap(c["topic"], c["type"])
    newest = tap.message()
    if newest is None:
        if not rt.publishers(c["topic"]):
            return CheckResult(FAIL, f"no publisher on {c['topic']}")
        return CheckResult(WAITING, f"waiting for a message on {c['topic']}")
    msg = newest[1]
    distance = math.dist((msg.x, msg.y), (c["x"], c["y"]))
    where = f"({c['x']:g}, {c['y']:g})"
    if distance >= c["at_least"]:
        return CheckResult(PASS, f"{c['topic']} is {distance:.2f} m from {where}")
    return CheckResult(
        WAITING, f"{c['topic']} is {distance:.2f} m from {where}; {c['at_least']:g} m needed"
    )
