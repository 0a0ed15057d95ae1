"""What a lesson check judged over time, kept with an exercise's result as a probe's trace.

An exercise is graded first on the lessons' checks. Most are yes-or-no (a node
on the graph), but ``topic_rate`` judges a quantity over a window: "/count at
8.58 Hz, expected 9.9-10.1 Hz" says less than the rate message by message,
with the band, the window that counted and where it stood at the end. This
turns the check's subscription into that trace; the attempt keeps and plots it
(``app.exercises.plots``) as it does a probe's.
"""

from __future__ import annotations

from collections.abc import Sequence

from app.exercises.trace import Trace, thinned
from app.lessons.runtime import LessonRuntime
from app.lessons.schema import Spec
from app.ros.monitor import Sample

# Each point is the rate over this many of the latest gaps: one late message
# shows as a dip, yet a single jittery gap does not fill the plot with noise.
GAPS_PER_POINT = 3


def check_traces(rt: LessonRuntime, spec: Spec, passed: bool, detail: str) -> tuple[Trace, ...]:
    """The trace of a ``topic_rate`` check judged by the publisher's clock (none otherwise)."""
    if spec.kind != "topic_rate" or spec.get("stamps", False):
        return ()
    key = (spec["topic"], spec["type"])
    tap = rt.tap(*key)
    samples = tap.samples()
    points, first = message_rates(samples)
    if not points or first is None:
        return ()
    since = [rt.tap_born.get(key, first)]
    if "since" in spec.fields:
        since.append(float(spec["since"]))
    if rt.changed_at is not None:
        since.append(rt.changed_at)
    judged_from = max(0.0, max(since) - first)
    low, high = float(spec["min_hz"]), float(spec["max_hz"])
    end = points[-1][0]
    return (
        Trace.of(
            f"rate of {spec['topic']}, message by message",
            "Hz",
            thinned(points),
            low=low,
            high=high,
            broken_at=None if passed else end,
            broken_why="" if passed else _verdict_words(detail),
            judged_from=judged_from,
            along="time since the first message (s)",
        ),
    )


def message_rates(samples: Sequence[Sample]) -> tuple[list[tuple[float, float]], float | None]:
    """``(time since the first arrival, rate over the last few gaps)`` per message, and the
    first arrival (monotonic). The publisher's stamps and sequence numbers when the
    middleware gives them (a lost message is one gap of two intervals, not half the
    rate), else the arrival times."""
    if len(samples) < 2:
        return [], None
    first = samples[0][0]
    stamped = all(stamp > 0 and seq is not None for _a, _s, stamp, seq, _w in samples)
    points: list[tuple[float, float]] = []
    for i in range(1, len(samples)):
        j = max(0, i - GAPS_PER_POINT)
        now, before = samples[i], samples[j]
        if stamped:
            span = (now[2] - before[2]) * 1e-9
            count = float((now[3] or 0) - (before[3] or 0))
        else:
            span, count = now[0] - before[0], float(i - j)
        if span > 0 and count > 0:  # a restarted publisher's sequence starts again
            points.append((now[0] - first, count / span))
    return points, first


def _verdict_words(detail: str) -> str:
    """The check's measured rate, short enough for the plot's marker: "8.58 Hz"."""
    words = detail.split(" at ", 1)[-1]
    return words.split(" over ", 1)[0] if " Hz" in words else "outside the band"
