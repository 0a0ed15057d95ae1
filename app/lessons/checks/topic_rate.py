"""Check ``topic_rate``: the topic is published at a rate inside the window, judged on enough
messages by the publisher's clock (or, with ``stamps``, by the messages' own header stamps:
a simulated sensor's rate per simulated second, whatever the computer's speed).
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check
from app.ros.monitor import TopicMonitor, stamped_rate_of

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
    optional="samples since stamps",
    words="the topic is published at a rate inside the window, judged on enough messages "
    "by the publisher's clock (with stamps = true, by the messages' header stamps: a "
    "simulated sensor's rate in simulated time, the same on a slow computer); after a "
    "step's button changed a parameter, only what was sent after that counts",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    """Judged on enough messages (``samples``, else about 1.5 s of the rate under test),
    by the publisher's clock where the middleware gives it, over a window (at
    least 5 s) as long as those messages need at the slowest accepted rate (older ones
    do not count). ``since`` (a probe's, not a lesson file's: ``time.monotonic()`` when
    it changed the rate) leaves out every message that arrived before it: a window that
    still held the old timer's messages read a mix of the two rates (8.987 Hz as 8.58).
    A lesson step's ``set_param`` button does the same for every rate judged after it
    (``rt.changed_at``: lesson 08 sets /greeting's rate in one step and measures it in
    the next; for about 5 s the window read a mix of 2 and 5 Hz)."""
    tap = rt.tap(c["topic"], c["type"])
    needed = rate_samples_needed(c)
    if c.get("stamps", False):
        return _by_stamps(rt, c, tap, needed)
    full = max(MIN_WINDOW_SEC, (needed + 1) / c["min_hz"]) if c["min_hz"] > 0 else None
    window, born = full, rt.tap_born.get((c["topic"], c["type"]), time.monotonic())
    since = [float(c["since"])] if "since" in c.fields else []
    if rt.changed_at is not None:
        since.append(rt.changed_at)
    if since:
        born = max(born, *since)
        window = min(full or math.inf, max(0.0, time.monotonic() - born))
    stats = tap.published_rate(window)
    got = 0 if stats is None else (stats.published or stats.received)
    listened = time.monotonic() - born
    if stats is None or (got < needed and (full is None or listened < full)):
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


def _by_stamps(rt: LessonRuntime, c: Spec, tap: TopicMonitor, needed: int) -> CheckResult:
    """The rate by the messages' header stamps, per second of the clock they are stamped
    with: /odom of a world running at 0.8x of real time is 30 Hz of simulated time (24 Hz
    of the wall clock's, which a wall-clock window would have failed)."""
    needed = min(needed, tap.keep)
    points = []
    for seq, msg in tap.sequenced(needed):
        header = getattr(msg, "header", None)
        if header is None:
            return CheckResult(FAIL, f"{c['type']} has no header stamps to judge a rate by")
        points.append((seq, header.stamp.sec * 1_000_000_000 + header.stamp.nanosec))
    found = stamped_rate_of(points)
    got = 0 if found is None else found[1]
    if found is None or got < needed:
        if not rt.publishers(c["topic"]):
            return CheckResult(FAIL, f"no publisher on {c['topic']}")
        return CheckResult(
            WAITING, f"measuring the rate of {c['topic']}: {got} of {needed} messages"
        )
    rate = found[0]
    text = f"{c['topic']} at {rate:.2f} Hz over {got} messages (by their header stamps)"
    if c["min_hz"] <= rate <= c["max_hz"]:
        return CheckResult(PASS, text)
    return CheckResult(FAIL, f"{text}, expected {c['min_hz']}-{c['max_hz']} Hz")
