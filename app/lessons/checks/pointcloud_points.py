"""Check ``pointcloud_points``: the newest point cloud on the topic has enough points."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "pointcloud_points",
    required="topic at_least",
    words="the newest point cloud on the topic has enough points",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    tap = rt.tap(c["topic"], "sensor_msgs/msg/PointCloud2")
    recent = tap.recent(1)
    if not recent:
        if not rt.publishers(c["topic"]):
            return CheckResult(FAIL, f"no publisher on {c['topic']}")
        return CheckResult(WAITING, f"waiting for a cloud on {c['topic']}")
    cloud = recent[-1][1]
    points = cloud.width * cloud.height
    if points >= c["at_least"]:
        return CheckResult(PASS, f"the cloud has {points} points")
    return CheckResult(WAITING, f"the cloud has {points} of {c['at_least']} points")
