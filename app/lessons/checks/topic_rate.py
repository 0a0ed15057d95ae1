"""Check ``topic_rate``: the topic is published at a rate inside the window, judged on enough
messages by the publisher's clock.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

# Without ``samples``, a rate is judged on about this long of the rate under test
# (a lesson's live check, e.g. a short bag replay); exercises ask for more.
RATE_SECONDS = 1.5
RATE_MIN_SAMPLES, RATE_MAX_SAMPLES = 3, 60
MIN_WINDOW_SEC = 5.0


def rate_samples_needed(check: Spec) -> int:
    """Messages a topic_rate check judges on: its ``samples``, else ~1.5 s at the mid rate."""
    if "samples" in check.fields:
        return int(check["samples"])
    mid = (float(check["min_hz"]) + float(check["max_hz"])) / 2
    return max(RATE_MIN_SAMPLES, min(RATE_MAX_SAMPLES, round(mid * RATE_SECONDS)))


@register_check(
    "topic_rate",
    required="topic type min_hz max_hz",
    optional="samples",
    words="the topic is published at a rate inside the window, judged on enough messages "
    "by the publisher's clock",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    """Judged on enough messages (``samples``, else about 1.5 s of the rate under test),
    by the publisher's clock where the middleware gives it, over a window (at
    least 5 s) as long as those messages need at the slowest accepted rate (older ones,
    e.g. from before a rate change, do not count)."""
    tap = rt.tap(c["topic"], c["type"])
    needed = rate_samples_needed(c)
    window = max(MIN_WINDOW_SEC, (needed + 1) / c["min_hz"]) if c["min_hz"] > 0 else None
    stats = tap.published_rate(window)
    got = 0 if stats is None else (stats.published or stats.received)
    listened = time.monotonic() - rt.tap_born.get((c["topic"], c["type"]), time.monotonic())
    if stats is None or (got < needed and (window is None or listened < window)):
        if not rt.publishers(c["topic"]):
            return CheckResult(FAIL, f"no publisher on {c['topic']}")
        return CheckResult(
            WAITING, f"measuring the rate of {c['topic']}: {got} of {needed} messages"
        )
    how = "by the publisher's clock" if not stats.fallback else "by arrival times"
    text = f"{c['topic']} at {stats.rate:.2f} Hz over {got} messages ({how})"
    if c["min_hz"] <= stats.rate <= c["max_hz"] and got >= needed:
        return CheckResult(PASS, text)
    return CheckResult(FAIL, f"{text}, expected {c['min_hz']}-{c['max_hz']} Hz")
