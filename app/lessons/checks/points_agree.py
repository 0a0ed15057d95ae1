"""Check ``points_agree``: two PointStamped topics give the same point for the same stamp.

Two nodes that transform the same camera point (a hand-made matrix and a tf2
lookup) copy the camera's stamp into their output; messages with equal
stamps are answers to the same question, and must name the same point in
the same frame, within the tolerance.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

POINT = "geometry_msgs/msg/PointStamped"
KEPT = 20  # recent messages of each topic searched for a shared stamp


@register_check(
    "points_agree",
    required="topic like tolerance",
    words="two PointStamped topics name the same point, in the same frame, for messages with "
    "the same time stamp (within a tolerance)",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    ours, theirs = rt.tap(c["topic"], POINT), rt.tap(c["like"], POINT)
    for tap in (ours, theirs):
        if not rt.publishers(tap.topic):
            return CheckResult(FAIL, f"no publisher on {tap.topic}")
    by_stamp = {(m.header.stamp.sec, m.header.stamp.nanosec): m for _t, m in theirs.recent(KEPT)}
    for _t, mine in reversed(ours.recent(KEPT)):  # the newest pair decides
        other = by_stamp.get((mine.header.stamp.sec, mine.header.stamp.nanosec))
        if other is None:
            continue
        a, b = mine.point, other.point
        if mine.header.frame_id != other.header.frame_id:
            return CheckResult(
                FAIL,
                f"{c['topic']} is in '{mine.header.frame_id}', {c['like']} in "
                f"'{other.header.frame_id}'",
            )
        off = math.dist((a.x, a.y, a.z), (b.x, b.y, b.z))
        text = (
            f"{c['topic']} ({a.x:.3f}, {a.y:.3f}, {a.z:.3f}) and {c['like']} "
            f"({b.x:.3f}, {b.y:.3f}, {b.z:.3f}) in '{mine.header.frame_id}'"
        )
        if off <= float(c["tolerance"]):
            return CheckResult(PASS, f"{text}: {off * 1000:.2f} mm apart")
        return CheckResult(FAIL, f"{text}: {off * 1000:.1f} mm apart")
    return CheckResult(
        WAITING, f"waiting for messages with the same stamp on {c['topic']} and {c['like']}"
    )
