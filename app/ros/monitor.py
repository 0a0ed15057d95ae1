"""One raw subscription behind echo, hz, bw, rates and lesson checks.

``TopicMonitor`` subscribes raw (serialized bytes), so sizes are known for
bandwidth and messages are deserialized only when someone looks at them.
The subscription callback (executor thread) is its single writer; readers on
any other thread take its lock and get copies.

The callback takes the middleware's message info too: the publisher's clock
(``source_timestamp``) and its per-writer ``publication_sequence_number``.
From those, ``published_rate`` tells how often the publisher *sent*, and how
many samples this subscription missed; arrival times alone (``rate``, as
`ros2 topic hz` computes it) only tell what got through, which is less when a
busy best-effort subscriber drops samples.
"""

from __future__ import annotations

import math
import threading
import time
from bisect import bisect_left
from collections import deque
from collections.abc import Hashable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from itertools import pairwise
from typing import Generic, TypedDict, TypeVar

from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message

from app.ros.qos import matching_qos

# One received sample: arrival (monotonic s), size (bytes), the publisher's
# clock (ns, 0 when unknown), its sequence number (None when unknown), and the
# writer it came from (None when the middleware does not say).
Sample = tuple[float, int, int, int | None, Hashable | None]

M = TypeVar("M")  # the topic's messages (their generated class is untyped)


class MessageInfo(TypedDict, total=False):
    """What rclpy hands a raw subscription's callback with each message (rmw's message info)."""

    source_timestamp: int  # ns, the publisher's clock
    received_timestamp: int  # ns, ours
    publication_sequence_number: int  # per writer
    reception_sequence_number: int
    publisher_gid: Mapping[str, Hashable]  # the writer ("data"); not in Jazzy's rclpy


# More breaks than this in one writer's sequence numbers within a window is
# not a publisher restarting: several publishers interleave.
MAX_RESTARTS = 2
# From this many samples of one publisher its rate is a line fitted through all of
# their stamps, not the span from the first to the last (see ``fitted_rate``).
MIN_FIT_SAMPLES = 3

NO_INFO = "the middleware gave no publisher timestamps or sequence numbers"
INTERLEAVED = "several publishers interleave and this rclpy does not say which sent each sample"
TOO_FEW = "too few samples from each publisher"


@dataclass(frozen=True)
class RateStats:
    rate: float
    min_period: float
    max_period: float
    std_dev: float
    window: int

    def ros2_text(self) -> str:
        return (
            f"average rate: {self.rate:.3f}\n"
            f"\tmin: {self.min_period:.3f}s max: {self.max_period:.3f}s "
            f"std dev: {self.std_dev:.5f}s window: {self.window}"
        )


@dataclass(frozen=True)
class PublishedRate:
    """How often the publishers sent, from their own clock and sequence numbers.

    With ``fallback`` set, the publishers' side could not be read (the reason
    is in it) and ``rate`` is what arrived here, as `ros2 topic hz` measures.
    """

    rate: float  # samples published per second (arrived per second on fallback)
    published: int | None  # samples published in the window, by sequence numbers
    received: int  # samples this subscription received in the window
    missed: int | None  # gaps in the sequence numbers
    writers: int = 1  # publishers told apart (their GIDs, when rclpy gives them)
    restarts: int = 0  # a writer's sequence starting over (a publisher restarted)
    fallback: str = ""

    def summary(self, why_missed: str = "", digits: int = 2) -> str:
        """'30.00 Hz published; this view missed 412 of 9,000 (why)', for a panel."""
        hz = f"{self.rate:.{digits}f} Hz"
        if self.fallback or self.published is None:
            return f"{hz} arrived (publisher's rate unknown: {self.fallback})"
        text = f"{hz} published"
        if self.restarts:
            text += " (the publisher restarted)"
        if not self.missed:
            return text + ", none missed"
        text += f"; this view missed {self.missed:,} of {self.published:,}"
        return text + (f" ({why_missed})" if why_missed else "")

    def ros2_line(self, why_missed: str = "") -> str:
        """The line `ros2 topic hz` gets after its own two."""
        if self.fallback or self.published is None:
            return f"\tpublished rate: unknown ({self.fallback}); the average above is what arrived"
        text = f"\tpublished rate: {self.rate:.3f} by the publisher's clock"
        if self.restarts:
            text += " (the publisher restarted)"
        if not self.missed:
            return text + f"; none of {self.published:,} missed"
        text += f"; this subscription missed {self.missed:,} of {self.published:,}"
        return text + (f" ({why_missed})" if why_missed else "")


@dataclass(frozen=True)
class BandwidthStats:
    bytes_per_sec: float
    count: int
    mean: float
    min_size: int
    max_size: int

    def ros2_text(self) -> str:
        return (
            f"{_human(self.bytes_per_sec)}/s from {self.count} messages\n"
            f"\tMessage size mean: {_human(self.mean)} min: {_human(self.min_size)} "
            f"max: {_human(self.max_size)}"
        )


def _human(size: float) -> str:
    for unit in ("B", "KB", "MB"):
        if size < 1000 or unit == "MB":
            return f"{size:.2f} {unit}"
        size /= 1000
    return f"{size:.2f} MB"


# ------------------------------------------------------------------ pure rate math


def arrival_rate(stamps: Sequence[float]) -> float | None:
    """(n - 1) / (last - first), as `ros2 topic hz` computes it; None if unmeasurable."""
    if len(stamps) < 2:
        return None
    span = stamps[-1] - stamps[0]
    return (len(stamps) - 1) / span if span > 0 else None


def _run_rate(run: list[int], points: list[tuple[int, int]]) -> float:
    """One run's samples per second: its fitted line, or first to last if too short."""
    rate = fitted_rate(points) if len(points) >= MIN_FIT_SAMPLES else None
    return rate or (run[2] - run[0]) / ((run[3] - run[1]) * 1e-9)


def _rate_kept_longest(spans: list[tuple[int, int, float]]) -> float:
    """The summed rate of the runs (start ns, end ns, rate) that overlap, over the stretch
    of time it held longest (a weighted median; stretches no run covers do not count).

    Not the mean over all the time covered: a view that matched one of two publishers a
    moment after the other never got that one's first samples, and the mean counted it
    as silent until then (ci113: 195.9 Hz for two publishers sending 200 together).
    """
    edges = sorted({t for start, end, _rate in spans for t in (start, end)})
    stretches: list[tuple[float, int]] = []  # (summed rate, length ns)
    for t0, t1 in pairwise(edges):
        active = [rate for start, end, rate in spans if start <= t0 and end >= t1]
        if active:
            stretches.append((sum(active), t1 - t0))
    stretches.sort()
    half, seen = sum(length for _rate, length in stretches) / 2, 0
    for rate, length in stretches:
        seen += length
        if seen >= half:
            return rate
    return stretches[-1][0]


def published_rate_of(samples: Sequence[Sample]) -> PublishedRate | None:
    """The publishers' rate and this subscription's misses over ``samples`` (arrival order).

    Sequence numbers count per writer. Samples are grouped by writer (when the
    middleware names it) and cut into runs wherever a writer's sequence does
    not go up (a restarted publisher starts again at 1). Where no writer is
    named, each sample continues the run whose last sequence number is the
    highest below its own, so two publishers' sequences are told apart; a run
    that begins where the earlier ones have ended is a restart. More runs than
    ``MAX_RESTARTS`` allows: the arrival rate (``INTERLEAVED``). Each run sent
    ``last - first + 1`` samples; its rate is a line fitted through its stamps
    (``fitted_rate``), so missed samples and one late stamp at an end of the
    window do not move it. Runs add up where they overlap in time, and the
    rate is the sum the runs kept for most of the time any of them covered
    (``_rate_kept_longest``): two concurrent writers add up, writers one after
    the other do not, and the pause of a restart does not count. Fewer than
    two samples: None.
    """
    n = len(samples)
    if n < 2:
        return None
    span = samples[-1][0] - samples[0][0]
    fallback_rate = (n - 1) / span if span > 0 else None

    def fallback(reason: str) -> PublishedRate | None:
        if fallback_rate is None:
            return None
        return PublishedRate(fallback_rate, None, n, None, writers=0, fallback=reason)

    # run: [first_seq, first_ns, last_seq, last_ns, received, first_index, last_index]
    open_runs: dict[Hashable | None, list[list[int]]] = {}
    runs: list[list[int]] = []
    points: dict[int, list[tuple[int, int]]] = {}  # id(run) -> its (seq, stamp), for its fit
    for index, (_arrival, _size, stamp, seq, writer) in enumerate(samples):
        if stamp <= 0 or seq is None:
            return fallback(NO_INFO)
        candidates = open_runs.setdefault(writer, [])
        # Unnamed writers (Jazzy's rclpy names none) may be several publishers: a sample
        # goes on the run it continues most closely. One message published from the
        # dashboard (sequence number 1) amid a talker's 50s used to join the talker's
        # run, which then seemed to have sent 58 samples this view never got (ci102).
        fits = [r for r in candidates if seq > r[2] and stamp >= r[3]]
        if fits:
            run = max(fits, key=lambda r: r[2])
            run[2], run[3] = seq, stamp
            run[4] += 1
            run[6] = index
            points[id(run)].append((seq, stamp))
            continue
        run = [seq, stamp, seq, stamp, 1, index, index]
        if writer is not None:
            candidates.clear()  # a named writer's sequence started over: it restarted
        candidates.append(run)
        runs.append(run)
        points[id(run)] = [(seq, stamp)]
        if len(runs) - len(open_runs) > MAX_RESTARTS:  # at once: a flood of runs costs n²
            return fallback(INTERLEAVED)
    restarts = _restarts(runs, samples)
    spans = [(r[1], r[3], _run_rate(r, points[id(r)])) for r in runs if r[3] > r[1]]
    if not spans:
        return fallback(TOO_FEW)
    published = sum(r[2] - r[0] + 1 for r in runs)
    rate = _rate_kept_longest(spans)
    return PublishedRate(
        rate=rate,
        published=published,
        received=n,
        missed=max(0, published - n),
        writers=len(open_runs),
        restarts=restarts,
    )


def _restarts(runs: list[list[int]], samples: Sequence[Sample]) -> int:
    """Runs that began where the same writer's earlier runs had all ended: a publisher that
    started its sequence again. A run that began while an earlier one went on is another
    publisher (only where the middleware names no writer can the two look alike)."""
    count = 0
    for i, run in enumerate(runs):
        writer = samples[run[5]][4]
        earlier = [r for r in runs[:i] if samples[r[5]][4] == writer]
        if earlier and all(r[6] < run[5] for r in earlier):
            count += 1
    return count


def fitted_rate(points: Sequence[tuple[int, int]]) -> float | None:
    """Samples per second from one publisher's (sequence number, stamp in ns): the
    least-squares slope of stamp against sequence number.

    A stamp is taken when the publisher got round to sending, a little after its timer
    fired (more on a loaded machine, never less). The first and last stamps alone carry
    that lateness straight into the rate (a 4 s window, last sample 45 ms late: 1.1 %
    low); a fit through every sample spreads it over all of them. Missed samples leave
    gaps in the sequence numbers and do not bend the line. None if it cannot be fitted.
    """
    n = len(points)
    if n < 2:
        return None
    seq0, ns0 = points[0]
    xs = [float(seq - seq0) for seq, _ in points]
    ys = [(ns - ns0) * 1e-9 for _, ns in points]
    mean_x, mean_y = sum(xs) / n, sum(ys) / n
    var = sum((x - mean_x) ** 2 for x in xs)
    if var <= 0:
        return None
    period = sum((x - mean_x) * (y - mean_y) for x, y in zip(xs, ys, strict=True)) / var
    return 1.0 / period if period > 0 else None


def stamped_rate_of(points: Sequence[tuple[int | None, int]]) -> tuple[float, int] | None:
    """(rate, messages sent) by the messages' own header stamps (ns), oldest first, each
    with the publisher's sequence number (None: counted as one after the other).

    A simulated sensor stamps with simulation time: its rate per simulated second is
    the same whatever share of the wall clock the computer gives the simulation. Only
    the newest run counts (stamps or sequence numbers going back: a reset or a restart).
    None with fewer than two messages in it.
    """
    numbered = [(k if seq is None else seq, ns) for k, (seq, ns) in enumerate(points)]
    start = len(numbered) - 1
    while start > 0 and (
        numbered[start - 1][0] < numbered[start][0] and numbered[start - 1][1] < numbered[start][1]
    ):
        start -= 1
    run = numbered[max(start, 0) :]
    if len(run) < 2:
        return None
    rate = fitted_rate(run)
    return None if rate is None else (rate, run[-1][0] - run[0][0] + 1)


def rate_stats_of(stamps: Sequence[float]) -> RateStats | None:
    """`ros2 topic hz`'s figures over arrival times (oldest first)."""
    if len(stamps) < 2:
        return None
    periods = [b - a for a, b in zip(stamps, stamps[1:], strict=False)]
    mean = (stamps[-1] - stamps[0]) / len(periods)
    if mean <= 0:
        return None
    std = math.sqrt(sum((p - mean) ** 2 for p in periods) / len(periods))
    return RateStats(1.0 / mean, min(periods), max(periods), std, len(stamps))


def why_missed(qos: QoSProfile | None) -> str:
    """One short phrase on why a subscription with this QoS can miss samples."""
    if qos is None:
        return ""
    if qos.reliability == ReliabilityPolicy.BEST_EFFORT:
        return "best effort: samples the middleware could not deliver are dropped, not resent"
    return (
        f"reliable, but keeps the last {qos.depth}: samples waiting while this view "
        "was busy were replaced by newer ones"
    )


def _arrival(sample: Sample) -> float:
    return sample[0]


class TopicMonitor(Generic[M]):
    """One raw subscription: arrival stamps, sizes, publisher info, and the last few messages.

    The subscription callback (executor thread) is the single writer; readers
    on other threads take the lock.
    """

    def __init__(
        self,
        node: Node,
        topic: str,
        msg_type: type[M],
        *,
        window: int = 10_000,
        keep: int = 100,
        qos: QoSProfile | int | None = None,
    ) -> None:
        # qos: a profile, a depth (reliable, volatile), or None to match the
        # topic's current publishers as `ros2 topic echo` does.
        self.topic = topic
        self.msg_type = msg_type
        if qos is None:
            qos = matching_qos(node, topic)
        elif isinstance(qos, int):
            qos = QoSProfile(depth=qos)  # what rclpy makes of a bare depth
        self.qos: QoSProfile = qos
        self._node = node
        self._cond = threading.Condition()
        self._samples: deque[Sample] = deque(maxlen=window)
        # (arrival wall time, raw message, the publisher's sequence number or None)
        self._recent: deque[tuple[float, bytes, int | None]] = deque(maxlen=keep)
        self.count = 0
        # Two parameters: rclpy passes the message info (a dict) as the second
        # (Jazzy's type hint only names the one-parameter form).
        self._sub = node.create_subscription(
            msg_type,
            topic,
            self._on_message,  # type: ignore[arg-type]
            qos,
            raw=True,
        )

    def _on_message(self, data: bytes, info: MessageInfo) -> None:
        now = time.monotonic()
        gid = info.get("publisher_gid")  # not in Jazzy's rclpy; newer ones name the writer
        sample = (
            now,
            len(data),
            info.get("source_timestamp") or 0,
            info.get("publication_sequence_number"),
            gid["data"] if gid else None,
        )
        with self._cond:
            self._samples.append(sample)
            self._recent.append((time.time(), data, sample[3]))
            self.count += 1
            self._cond.notify_all()

    def _window(self, window_sec: float | None) -> list[Sample]:
        with self._cond:
            samples = list(self._samples)
        if window_sec is not None:
            start = bisect_left(samples, time.monotonic() - window_sec, key=_arrival)
            samples = samples[start:]
        return samples

    def samples(self, window_sec: float | None = None) -> list[Sample]:
        """The kept samples (arrival, size, source stamp, sequence, writer), oldest first."""
        return self._window(window_sec)

    def wait_for_count(self, count: int, timeout: float) -> bool:
        """Block (not the executor thread) until ``count`` messages arrived in total."""
        with self._cond:
            return self._cond.wait_for(lambda: self.count >= count, timeout)

    def message(self, index_from_end: int = 1) -> tuple[float, M] | None:
        with self._cond:
            if len(self._recent) < index_from_end:
                return None
            stamp, data, _seq = self._recent[-index_from_end]
        return stamp, deserialize_message(data, self.msg_type)

    def recent(self, last: int | None = None) -> list[tuple[float, M]]:
        """The newest ``last`` kept messages (all kept ones for None), oldest first."""
        with self._cond:
            raw = list(self._recent)
        if last is not None:
            raw = raw[-last:] if last > 0 else []
        return [(stamp, deserialize_message(data, self.msg_type)) for stamp, data, _ in raw]

    def sequenced(self, last: int) -> list[tuple[int | None, M]]:
        """The newest ``last`` kept messages with the publisher's sequence number (None when
        the middleware does not give it), oldest first: a check that reads a message's own
        stamps counts the messages the publisher sent between them."""
        with self._cond:
            raw = list(self._recent)[-last:] if last > 0 else []
        return [(seq, deserialize_message(data, self.msg_type)) for _, data, seq in raw]

    @property
    def keep(self) -> int:
        """How many messages are kept to look back on."""
        return self._recent.maxlen or 0

    def newest(self) -> Iterator[tuple[float, M]]:
        """Kept messages newest first, each deserialised only when reached."""
        with self._cond:
            raw = list(self._recent)
        for stamp, data, _seq in reversed(raw):
            yield stamp, deserialize_message(data, self.msg_type)

    def rate_hz(self, window_sec: float = 5.0) -> float | None:
        """The publishing rate over the last ``window_sec`` (by the publisher's clock
        where the middleware says it, so samples this view missed do not lower it);
        None with fewer than two messages."""
        stats = self.published_rate(window_sec)
        return stats.rate if stats else None

    def messages_since(self, count_before: int) -> list[tuple[float, M]]:
        """Messages that arrived after the total count was ``count_before`` (as kept)."""
        with self._cond:
            fresh = min(self.count - count_before, len(self._recent))
            raw = list(self._recent)[len(self._recent) - fresh :] if fresh > 0 else []
        return [(stamp, deserialize_message(data, self.msg_type)) for stamp, data, _ in raw]

    def rate(self, window_sec: float | None = None) -> RateStats | None:
        """What arrived here, as `ros2 topic hz` reports it (lower than sent when samples drop)."""
        return rate_stats_of([s[0] for s in self._window(window_sec)])

    def published_rate(self, window_sec: float | None = None) -> PublishedRate | None:
        """How often the publishers sent, and how many samples this subscription missed."""
        return published_rate_of(self._window(window_sec))

    def why_missed(self) -> str:
        """Why this subscription can miss samples, in one phrase (its QoS)."""
        return why_missed(self.qos)

    def bandwidth(self, window_sec: float | None = None) -> BandwidthStats | None:
        samples = self._window(window_sec)
        if len(samples) < 2:
            return None
        span = samples[-1][0] - samples[0][0]
        values = [s[1] for s in samples]
        if span <= 0:
            return None
        return BandwidthStats(
            sum(values[1:]) / span, len(values), sum(values) / len(values), min(values), max(values)
        )

    def matched_publishers(self) -> int:
        """Writers this subscription is matched with (DDS endpoint matching, which the
        ROS graph can show well before: a message sent before it is not received)."""
        return int(self._sub.get_publisher_count())

    def close(self) -> None:
        self._node.destroy_subscription(self._sub)
