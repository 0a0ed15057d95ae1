"""Check ``tf_transform``: a tf2 lookup between two frames gives the expected transform."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from rclpy.time import Time
from tf2_ros import TransformException

from app.lessons.checks._tf_watch import nobody_publishes, watch_of
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check
from app.ros.rotations import quaternion_from_rpy, rotation_angle, rpy_of

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

DEFAULT_ANGLE_TOLERANCE = 0.02  # rad, about 1 degree


@register_check(
    "tf_transform",
    required="target source tolerance",
    optional="x y z roll pitch yaw angle_tolerance",
    words="the latest transform from the source frame into the target frame (what "
    "tf2_echo TARGET SOURCE prints) equals a value, within a tolerance (a wrong value of "
    "static frames fails; moving ones are waited for)",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    """``lookup_transform(target, source, Time())``: the newest transform, through the chain."""
    watch = watch_of(rt)
    target, source = c["target"], c["source"]
    try:
        t = watch.buffer.lookup_transform(target, source, Time())
    except TransformException as exc:
        if nobody_publishes(rt):
            return CheckResult(FAIL, "nobody publishes /tf or /tf_static")
        return CheckResult(WAITING, f"no transform from '{source}' to '{target}' yet: {exc}")
    v, r = t.transform.translation, t.transform.rotation
    got = (v.x, v.y, v.z)
    want = (float(c.get("x", 0.0)), float(c.get("y", 0.0)), float(c.get("z", 0.0)))
    rpy = (float(c.get("roll", 0.0)), float(c.get("pitch", 0.0)), float(c.get("yaw", 0.0)))
    quat = (r.x, r.y, r.z, r.w)
    off = math.dist(got, want)
    turn = rotation_angle(quat, quaternion_from_rpy(*rpy))
    text = (
        f"'{source}' in '{target}': translation [{got[0]:.3f}, {got[1]:.3f}, {got[2]:.3f}], "
        "rpy [{:.3f}, {:.3f}, {:.3f}]".format(*rpy_of(*quat))
    )
    if off <= float(c["tolerance"]) and turn <= float(
        c.get("angle_tolerance", DEFAULT_ANGLE_TOLERANCE)
    ):
        return CheckResult(PASS, text)
    # A moving chain may still get there (a turtle on its way): wait; a static one will not.
    return CheckResult(
        FAIL if watch.all_static(target, source) else WAITING,
        f"{text}; expected [{want[0]:g}, {want[1]:g}, {want[2]:g}], "
        f"rpy [{rpy[0]:g}, {rpy[1]:g}, {rpy[2]:g}] ({off:.3f} m and {turn:.3f} rad off)",
    )
