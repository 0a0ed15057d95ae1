"""Check ``bag_contains``: a finished bag in your bags folder holds enough messages of the
topic.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.bags.errors import BagError
from app.bags.folder import existing_path
from app.bags.info import read_info
from app.lessons.registry import FAIL, PASS, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "bag_contains",
    required="bag topic at_least",
    words="a finished bag in your bags folder holds enough messages of the topic",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    """A finished, readable bag in the learner's bags folder holds enough of a topic."""
    try:
        info = read_info(existing_path(c["bag"]))
    except BagError as exc:  # absent, still recording (no metadata yet), or unreadable
        return CheckResult(FAIL, str(exc))
    count = next((t.count for t in info.topics if t.name == c["topic"]), 0)
    if count >= c["at_least"]:
        return CheckResult(PASS, f"{c['bag']} holds {count} messages of {c['topic']}")
    return CheckResult(FAIL, f"{c['bag']} holds {count} of {c['at_least']} on {c['topic']}")
