"""Check ``tf_frame``: a frame is in the TF tree with the given parent."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.checks._tf_watch import known_text, nobody_publishes, watch_of
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "tf_frame",
    required="frame parent",
    words="a frame is in the TF tree (on /tf or /tf_static) with the given parent",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    watch = watch_of(rt)
    info = watch.frame(c["frame"])
    if info is None:
        if nobody_publishes(rt):
            return CheckResult(FAIL, "nobody publishes /tf or /tf_static")
        children = watch.parent_of_others(c["frame"])
        if children:
            return CheckResult(
                WAITING,
                f"'{c['frame']}' is only a parent so far (of {', '.join(children)}): "
                "child_frame_id names the frame described, header.frame_id its parent",
            )
        return CheckResult(WAITING, f"no frame '{c['frame']}' yet ({known_text(watch)})")
    where = "/tf_static" if info.static else "/tf"
    if info.parent != c["parent"]:
        return CheckResult(
            FAIL,
            f"'{c['frame']}' has the parent '{info.parent}' on {where}; expected '{c['parent']}'",
        )
    return CheckResult(PASS, f"'{c['frame']}' is a child of '{info.parent}' on {where}")
