"""Check ``arm_reached``: the arm's gripper is within the tolerance of the target point."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "arm_reached",
    required="tolerance",
    words="the arm's gripper is within the tolerance of the target point",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    target_tap = rt.tap("/pos_in_robot_base_frame", "geometry_msgs/msg/PointStamped")
    pose_tap = rt.tap("/end_effector_pose", "geometry_msgs/msg/PoseStamped")
    target, pose = target_tap.recent(1), pose_tap.recent(1)
    if not target or not pose:
        if not rt.publishers("/end_effector_pose"):
            return CheckResult(FAIL, "no arm is publishing /end_effector_pose")
        return CheckResult(WAITING, "waiting for a target and the arm's pose")
    t, p = target[-1][1].point, pose[-1][1].pose.position
    error = math.dist((t.x, t.y, t.z), (p.x, p.y, p.z))
    if error <= c["tolerance"]:
        return CheckResult(PASS, f"the gripper is {error * 1000:.0f} mm from the target")
    return CheckResult(WAITING, f"the gripper is {error * 1000:.0f} mm from the target")
