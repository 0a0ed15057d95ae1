"""Check ``topic_messages``: enough messages arrived on the topic (optionally with a field
containing a text).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "topic_messages",
    required="topic type at_least",
    optional="field contains",
    words="enough messages arrived on the topic (optionally with a field containing a text)",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    tap = rt.tap(c["topic"], c["type"])
    if c.get("field"):
        # Newest first, and no further than needed: images are big to decode.
        count = 0
        for _, msg in tap.newest():
            count += c.get("contains", "") in str(getattr(msg, c["field"]))
            if count >= c["at_least"]:
                break
    else:
        count = tap.count
    if count >= c["at_least"]:
        return CheckResult(PASS, f"{count} matching messages on {c['topic']}")
    if not rt.publishers(c["topic"]):
        return CheckResult(FAIL, f"no publisher on {c['topic']}")
    return CheckResult(WAITING, f"{count} of {c['at_least']} messages on {c['topic']}")
