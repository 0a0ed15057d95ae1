"""Check ``topic_subscribers``: enough nodes (not the dashboard) subscribe to the topic."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, CheckResult, register_check
from app.ros.graph import subscriptions_ours_and_others

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "topic_subscribers",
    required="topic at_least",
    words="enough nodes (not the dashboard) subscribe to the topic",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    # Count the learner's subscribers, not the dashboard's own taps (nor the grader's, and
    # its recording of the attempt, when an exercise's check runs).
    _ours, count = subscriptions_ours_and_others(rt.node, c["topic"])
    if count >= c["at_least"]:
        return CheckResult(PASS, f"{count} {_subscribers(count)} on {c['topic']}")
    wanted = c["at_least"]
    return CheckResult(FAIL, f"{count} of {wanted} {_subscribers(wanted)} on {c['topic']}")


def _subscribers(n: int) -> str:
    return "subscriber" if n == 1 else "subscribers"
