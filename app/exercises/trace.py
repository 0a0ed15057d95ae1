"""A quantity a probe judged over time: what the plot of a result draws.

"Came within 0.21 m of the wall (bound 0.35 m)" is one number of a run the
learner never saw. A probe that judges a quantity over time (the distance to
the wall ahead, to the goal, to the wall beside; a turtle's distance after
each jump) hands the series it judged with its result: the values, the band
they had to stay in, and the moment the verdict turned. ``app.exercises.plots``
draws it; the attempt's folder keeps it as JSON beside the bag.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, TypedDict


class TraceJson(TypedDict):
    """A trace as ``Trace.to_json`` writes it (the attempt's folder keeps a list of these)."""

    title: str
    unit: str
    times: list[float]
    values: list[float]
    low: float | None
    high: float | None
    broken_at: float | None
    broken_why: str
    judged_from: float
    along: str
    levels: list[str]
    expected: list[float]


@dataclass(frozen=True)
class Trace:
    """One series a probe judged, with what it was judged against."""

    title: str  # "distance to the wall ahead, trial 1"
    unit: str  # of the values: "m", "Hz", "rad"
    times: tuple[float, ...]  # seconds since the trial began (simulated time in the world)
    values: tuple[float, ...]
    low: float | None = None  # a value below this broke the rule (None: no lower bound)
    high: float | None = None  # ... above this
    broken_at: float | None = None  # the moment the verdict turned against the node
    broken_why: str = ""  # a few words at that moment: "0.21 m < 0.35 m"
    judged_from: float = 0.0  # values before this time were not judged (a settling time)
    along: str = "simulated time (s)"  # what the times count: the plot's x axis
    levels: tuple[str, ...] = ()  # named values (a state machine): value i means levels[i]
    expected: tuple[float, ...] = ()  # what the values should have been, at the same times

    @classmethod
    def of(
        cls,
        title: str,
        unit: str,
        points: Sequence[tuple[float, float]],
        *,
        low: float | None = None,
        high: float | None = None,
        broken_at: float | None = None,
        broken_why: str = "",
        judged_from: float = 0.0,
        along: str = "simulated time (s)",
        levels: Sequence[str] = (),
        expected: Sequence[float] = (),
    ) -> Trace:
        """A trace of ``(time, value)`` points; non-finite values are left out (and then
        ``expected``, which goes with the points one for one, is not kept)."""
        kept = [(t, v) for t, v in points if math.isfinite(t) and math.isfinite(v)]
        return cls(
            title,
            unit,
            tuple(round(t, 3) for t, _ in kept),
            tuple(round(v, 4) for _, v in kept),
            low,
            high,
            broken_at,
            broken_why,
            judged_from,
            along,
            tuple(levels),
            tuple(expected) if len(kept) == len(points) == len(expected) else (),
        )

    def outside(self, value: float) -> bool:
        """Whether ``value`` breaks the band."""
        return (self.low is not None and value < self.low) or (
            self.high is not None and value > self.high
        )

    def first_outside(self) -> tuple[float, float] | None:
        """The first judged ``(time, value)`` outside the band, if any."""
        for t, v in zip(self.times, self.values, strict=True):
            if t >= self.judged_from and self.outside(v):
                return t, v
        return None

    def to_json(self) -> TraceJson:
        return {
            "title": self.title,
            "unit": self.unit,
            "times": list(self.times),
            "values": list(self.values),
            "low": self.low,
            "high": self.high,
            "broken_at": self.broken_at,
            "broken_why": self.broken_why,
            "judged_from": self.judged_from,
            "along": self.along,
            "levels": list(self.levels),
            "expected": list(self.expected),
        }

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Trace:
        """The inverse of ``to_json``; raises ValueError on anything else."""
        try:
            times = tuple(float(t) for t in data["times"])
            values = tuple(float(v) for v in data["values"])
            if len(times) != len(values):
                raise ValueError("times and values differ in length")

            def number(key: str) -> float | None:
                value = data.get(key)
                return None if value is None else float(value)

            return cls(
                str(data["title"]),
                str(data["unit"]),
                times,
                values,
                number("low"),
                number("high"),
                number("broken_at"),
                str(data.get("broken_why", "")),
                float(data.get("judged_from", 0.0)),
                str(data.get("along", "simulated time (s)")),
                tuple(str(level) for level in data.get("levels", ())),
                tuple(float(v) for v in data.get("expected", ())),
            )
        except (KeyError, TypeError) as exc:
            raise ValueError(f"not a trace: {exc}") from None


def thinned(points: Sequence[tuple[float, float]], most: int = 400) -> list[tuple[float, float]]:
    """At most about ``most`` points, in time order: each stretch keeps its lowest and
    highest value, so a plot still shows the extreme that broke a bound."""
    if len(points) <= most:
        return list(points)
    buckets = max(1, most // 2)
    size = len(points) / buckets
    kept: list[tuple[float, float]] = []
    for b in range(buckets):
        stretch = points[int(b * size) : int((b + 1) * size)]
        if not stretch:
            continue
        extremes = {min(stretch, key=lambda p: p[1]), max(stretch, key=lambda p: p[1])}
        kept.extend(sorted(extremes))
    return kept
