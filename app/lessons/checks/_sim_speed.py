"""How fast simulated time runs against the wall clock, and what the world says it achieved.

sim_world publishes ``/clock`` (simulation time) and, once a wall-clock second,
``/real_time_factor`` (std_msgs/Float64): the simulated seconds it really
advanced per wall-clock second since the report before. Both are stamped by the
middleware with the world's own wall clock (``source_timestamp``), so the
factor is measured on the publisher's clock: a busy dashboard that hears the
messages late, or drops some, reads the same factor.

One watch per ``LessonRuntime`` (as the TF watch), while checks read it: its callbacks only store;
the check reads a copy under the lock and never blocks. The math is in plain
functions below, testable without ROS.
"""

from __future__ import annotations

import math
import threading
import time
from bisect import bisect_left
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64

from app.ros.monitor import MessageInfo

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime

REPORTS = "/real_time_factor"
# Best effort: the world is never slowed by us; a dropped /clock sample costs nothing,
# since each one carries its own wall and simulation time.
CLOCK_QOS = QoSProfile(depth=200, reliability=ReliabilityPolicy.BEST_EFFORT)
REPORT_QOS = QoSProfile(depth=10)
CLOCK_KEEP = 8000  # /clock samples: 40 s at 2x (200 Hz), 8 s at 10x
REPORT_KEEP = 30  # one a second
STILL = 0.01  # sim s per wall s below which simulated time stands still
SPAN_SLACK = 0.1  # s: reports a second apart, a span of 2 s may read 1.99 s


@dataclass(frozen=True)
class Report:
    """One /real_time_factor message: the world's wall time (s), its sequence number."""

    wall: float
    seq: int | None
    factor: float


@dataclass(frozen=True)
class SimSpeed:
    """Over one span of the world's wall clock: /clock's slope and the world's reports."""

    measured: float  # simulated s per wall s, from /clock (its samples either side of each end)
    reported: float  # the same, as the world reported it (its reports over the span)
    wall_span: float  # s of wall-clock time judged
    samples: int  # /clock samples in the span


def sim_at(points: Sequence[tuple[float, float]], wall: float) -> float | None:
    """Simulation time at a wall time, between the /clock samples either side of it.

    Samples are 1 / clock_rate of simulation time apart (0.01 s), so the estimate is
    off by less than that even across a stall (a starved world steps nothing, then
    catches up in a burst); None outside the samples.
    """
    at = bisect_left(points, wall, key=lambda p: p[0])
    if at == len(points) or (at == 0 and points[0][0] > wall):
        return None
    w1, s1 = points[at]
    if w1 == wall or at == 0:
        return s1
    w0, s0 = points[at - 1]
    return s0 + (s1 - s0) * (wall - w0) / (w1 - w0)


def newest_run(clock: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """The newest /clock samples since simulation time last went back (a reset to 0)."""
    start = len(clock) - 1
    while start > 0 and clock[start - 1][1] <= clock[start][1]:
        start -= 1
    return list(clock[max(start, 0) :])


def consecutive_reports(reports: Sequence[Report]) -> list[Report]:
    """The newest reports with no report lost between them (by sequence numbers)."""
    run = list(reports[-1:])
    for report in reversed(reports[:-1]):
        newer = run[0]
        if report.wall >= newer.wall:
            break
        if report.seq is not None and newer.seq is not None and newer.seq != report.seq + 1:
            break
        run.insert(0, report)
    return run


def sim_speed(
    clock: Sequence[tuple[float, float]], reports: Sequence[Report], seconds: float
) -> SimSpeed | str:
    """/clock's sim s per wall s over the newest span of the world's reports that
    lasts ``seconds`` of its wall clock, with what the reports say of that span; a
    reason string while there is not enough to judge.

    A report covers the wall time since the report before it (a starved world's
    timer may fire twice in a row, so the span is counted in seconds, not reports);
    the reported factor over the span is the reports' time-weighted mean.
    """
    run_points = newest_run(clock)
    newest = run_points[-1][0] if run_points else -math.inf
    judged = list(reports)
    while len(judged) > 1 and judged[-1].wall > newest and judged[-1].factor >= STILL:
        judged.pop()  # time ran until then: the /clock samples after it are on their way
    run = consecutive_reports(judged)
    first = next(
        (
            i
            for i in range(len(run) - 2, -1, -1)
            if run[-1].wall - run[i].wall >= seconds - SPAN_SLACK
        ),
        None,
    )
    if first is None:
        heard = run[-1].wall - run[0].wall if run else 0.0
        return f"{heard:.1f} of {seconds:g} s of the world's reports on {REPORTS}"
    run = run[first:]
    start, end = run[0].wall, run[-1].wall
    span = end - start
    reported = sum(b.factor * (b.wall - a.wall) for a, b in zip(run, run[1:], strict=False))
    reported /= span
    begin, finish = sim_at(run_points, start), sim_at(run_points, end)
    samples = sum(1 for w, _ in run_points if start <= w <= end)
    if begin is None or finish is None:
        if reported < STILL and samples == 0:  # paused: the world says time stood still
            return SimSpeed(0.0, reported, span, 0)
        return f"{samples} /clock samples over the last {span:.1f} s of the world's reports"
    return SimSpeed((finish - begin) / span, reported, span, samples)


def factor_text(value: float) -> str:
    """'2x', '1.6x', '1.02x': as few digits as tell it."""
    for digits in (0, 1, 2):
        if abs(value - round(value, digits)) < 0.005:
            return f"{value:.{digits}f}x"
    return f"{value:.2f}x"


class SimSpeedWatch:
    """/clock and /real_time_factor, each sample with the world's own wall time."""

    def __init__(self, node: Node) -> None:
        self.node = node
        self.lock = threading.Lock()
        self.clock: deque[tuple[float, float]] = deque(maxlen=CLOCK_KEEP)
        self.reports: deque[Report] = deque(maxlen=REPORT_KEEP)
        self.by_arrival = False  # the middleware gave no source timestamps: arrival instead
        # Two parameters: rclpy passes the message info (a dict) as the second.
        self._subscriptions = [
            node.create_subscription(Clock, "/clock", self._on_clock, CLOCK_QOS),  # type: ignore[arg-type]
            node.create_subscription(Float64, REPORTS, self._on_report, REPORT_QOS),  # type: ignore[arg-type]
        ]

    def _wall(self, info: MessageInfo) -> float:
        stamp = info.get("source_timestamp") or 0
        if stamp > 0:
            return stamp * 1e-9
        self.by_arrival = True
        return time.time()

    def _on_clock(self, msg: Clock, info: MessageInfo) -> None:
        sample = (self._wall(info), msg.clock.sec + msg.clock.nanosec * 1e-9)
        with self.lock:
            self.clock.append(sample)

    def _on_report(self, msg: Float64, info: MessageInfo) -> None:
        report = Report(self._wall(info), info.get("publication_sequence_number"), msg.data)
        with self.lock:
            self.reports.append(report)

    def newest_report(self) -> Report | None:
        with self.lock:
            return self.reports[-1] if self.reports else None

    def speed(self, seconds: float) -> SimSpeed | str:
        with self.lock:
            clock, reports = list(self.clock), list(self.reports)
        return sim_speed(clock, reports, seconds)

    def close(self) -> None:
        for subscription in self._subscriptions:
            try:
                self.node.destroy_subscription(subscription)
            except Exception:  # the node is gone already: nothing left to free
                pass
        self._subscriptions = []


def speed_watch_of(rt: LessonRuntime) -> SimSpeedWatch:
    """The runtime's sim-speed watch, subscribed on its node at the first use; the runtime
    closes it once no check reads it (/clock comes at 100 Hz or more)."""
    return rt.watch("sim_speed", SimSpeedWatch)
