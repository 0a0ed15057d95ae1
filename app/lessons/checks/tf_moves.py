"""Check ``tf_moves``: a frame moves, relative to its parent or to a given frame."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, cast

from rclpy.time import Time
from tf2_ros import TransformException

from app.lessons.checks._tf_watch import known_text, nobody_publishes, watch_of
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check
from app.ros.rotations import rotation_angle

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

# Where a frame was: its translation and rotation (x, y, z, w).
_Placement = tuple[tuple[float, float, float], tuple[float, float, float, float]]


@register_check(
    "tf_moves",
    required="frame at_least",
    optional="relative_to",
    words="a frame moves (at least so many metres, or radians of turn) relative to its "
    "parent or to a given frame, from where it was when the check began",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    watch = watch_of(rt)
    frame = c["frame"]
    info = watch.frame(frame)
    if info is None:
        if nobody_publishes(rt):
            return CheckResult(FAIL, "nobody publishes /tf or /tf_static")
        return CheckResult(WAITING, f"no frame '{frame}' yet ({known_text(watch)})")
    reference = c.get("relative_to", info.parent)
    if info.static and "relative_to" not in c.fields:
        return CheckResult(
            FAIL, f"'{frame}' is a static frame (on /tf_static): it never moves in '{reference}'"
        )
    try:
        t = watch.buffer.lookup_transform(reference, frame, Time())
    except TransformException as exc:
        return CheckResult(WAITING, f"no transform from '{frame}' to '{reference}' yet: {exc}")
    v, r = t.transform.translation, t.transform.rotation
    now = ((v.x, v.y, v.z), (r.x, r.y, r.z, r.w))
    start = cast(_Placement, watch.memory.setdefault(c.key, now))
    moved = math.dist(start[0], now[0])
    turned = rotation_angle(start[1], now[1])
    text = f"'{frame}' moved {moved:.2f} m and turned {turned:.2f} rad in '{reference}'"
    if max(moved, turned) >= float(c["at_least"]):
        return CheckResult(PASS, text)
    return CheckResult(WAITING, f"{text}; {c['at_least']:g} needed")
