"""Check ``topic_subscribers``: enough nodes (not the dashboard) subscribe to the topic."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, CheckResult, register_check
from app.ros.names import own_nodes

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
    infos = rt.node.get_subscriptions_info_by_topic(c["topic"])
    ours = own_nodes(rt.node.get_name(), rt.node.get_namespace())
    count = sum(1 for info in infos if (info.node_name, info.node_namespace) not in ours)
    if count >= c["at_least"]:
        return CheckResult(PASS, f"{count} {_subscribers(count)} on {c['topic']}")
    wanted = c["at_least"]
    return CheckResult(FAIL, f"{count} of {wanted} {_subscribers(wanted)} on {c['topic']}")


def _subscribers(n: int) -> str:
    return "subscriber" if n == 1 else "subscribers"
