"""Live rates of a changing set of topics, measured cheaply.

One best-effort raw ``TopicMonitor`` per watched topic: best effort so a
reliable publisher is never slowed by us, raw so an image or a point cloud is
counted, never deserialized. The set of watched topics is capped, and
changed only when the caller's wish list changes.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

from rclpy.node import Node

from app.ros.convert import ConversionError, import_type
from app.ros.monitor import TopicMonitor
from app.ros.qos import MEASURE_QOS

log = logging.getLogger(__name__)

MAX_WATCHED = 30
RATE_WINDOW_SEC = 3.0
# A slow topic has few messages in 3 s: at 2 Hz, one message 0.1 s late moves the
# figure from 2.0 to 1.9 Hz. Its window widens to hold this many intervals (up to
# MAX_RATE_WINDOW_SEC), so one late message moves it by about 1 %.
MIN_INTERVALS = 10
MAX_RATE_WINDOW_SEC = 10.0


def steady_rate(rate_hz: Callable[[float], float | None], window_sec: float) -> float:
    """``rate_hz(window)`` over ``window_sec``, or over a window wide enough for
    MIN_INTERVALS intervals when that holds fewer; 0.0 when silent in ``window_sec``."""
    rate = rate_hz(window_sec)
    if rate is None:
        return 0.0
    if 0 < rate * window_sec < MIN_INTERVALS:
        rate = rate_hz(min(MAX_RATE_WINDOW_SEC, MIN_INTERVALS / rate)) or rate
    return rate


class RateHold:
    """Rates as a drawing shows them: held against jitter, never held at a rough first figure.

    A steady topic's figure wobbles (2.0, 1.99, 2.01 Hz); a drawing that redraws
    on every wobble restarts its animation, so a shown rate changes only when a
    reading moves by ``change`` (a share of it). But the first readings of a
    topic come from a couple of messages: one a little late reads 1.9 Hz, and a
    hold would keep that rough figure for good. So while the measurement is
    still filling its window (MIN_INTERVALS intervals, at most
    MAX_RATE_WINDOW_SEC after the topic was first heard), any reading that
    reads differently (``rate_text``) replaces the shown one.
    """

    def __init__(self, change: float, clock: Callable[[], float] = time.monotonic) -> None:
        self._change = change
        self._clock = clock
        self._held: dict[str, tuple[float, float]] = {}  # topic -> (shown rate, heard since)

    def shown(self, topic: str, rate: float) -> float:
        """The rate to show for ``topic`` given its latest reading (0.0: silent)."""
        now = self._clock()
        held = self._held.get(topic)
        if held is None or (rate > 0) != (held[0] > 0):  # first reading, or heard / silent
            self._held[topic] = (rate, now)
            return rate
        shown, since = held
        settling = rate > 0 and now - since < min(MAX_RATE_WINDOW_SEC, MIN_INTERVALS / rate)
        if settling:
            moved = rate_text(rate) != rate_text(shown)
        else:
            moved = abs(rate - shown) > self._change * max(shown, 0.1)
        if moved:
            self._held[topic] = (rate, since)
            return rate
        return shown


class RateBoard:
    """Rates of a changing set of topics; ``watch`` from one thread, ``rate`` from any."""

    def __init__(self, node: Node, limit: int = MAX_WATCHED) -> None:
        self._node = node
        self._limit = limit
        self._lock = threading.Lock()
        self._monitors: dict[str, tuple[str, TopicMonitor[object]]] = {}

    def watch(self, topics: dict[str, str]) -> None:
        """Measure exactly these topics (name -> type), at most ``limit`` of them."""
        wanted = dict(sorted(topics.items())[: self._limit])
        with self._lock:
            stale = [t for t, (kind, _m) in self._monitors.items() if wanted.get(t) != kind]
            dropped = [self._monitors.pop(t)[1] for t in stale]
            missing = [t for t in wanted if t not in self._monitors]
        for monitor in dropped:
            monitor.close()
        for topic in missing:
            try:
                msg_type = import_type(wanted[topic], "msg")
            except ConversionError:
                continue  # a type this environment does not have: no rate, no crash
            monitor = TopicMonitor(self._node, topic, msg_type, window=200, keep=1, qos=MEASURE_QOS)
            with self._lock:
                self._monitors[topic] = (wanted[topic], monitor)

    def watched(self) -> list[str]:
        with self._lock:
            return sorted(self._monitors)

    def rate(self, topic: str, window_sec: float = RATE_WINDOW_SEC) -> float | None:
        """Messages per second over the last few seconds (longer for a slow topic: at least
        MIN_INTERVALS intervals); 0.0 when silent in ``window_sec``, None if unwatched."""
        with self._lock:
            entry = self._monitors.get(topic)
        if entry is None:
            return None
        return steady_rate(entry[1].rate_hz, window_sec)  # as published, not as received

    def latest(self, topic: str) -> tuple[float, object] | None:
        """The newest message of a watched topic with its arrival time (wall clock), or None."""
        with self._lock:
            entry = self._monitors.get(topic)
        return None if entry is None else entry[1].message()

    def heard(self, topic: str, window_sec: float = RATE_WINDOW_SEC) -> bool:
        """Whether a message of ``topic`` arrived in the last ``window_sec``."""
        with self._lock:
            entry = self._monitors.get(topic)
        return entry is not None and bool(entry[1].samples(window_sec))

    def close(self) -> None:
        with self._lock:
            monitors = [m for _kind, m in self._monitors.values()]
            self._monitors = {}
        for monitor in monitors:
            monitor.close()


class SharedRates:
    """One ``RateBoard`` for several views of the graph (the Graph tab, the stage's graph and plot).

    Each drawing says which topics it wants; the board measures their union, so
    a topic two drawings show is subscribed once (a 1 kHz topic costs per
    subscription).
    """

    def __init__(self, node: Node) -> None:
        self._board = RateBoard(node)
        self._lock = threading.Lock()
        self._wishes: dict[int, dict[str, str]] = {}

    def client(self) -> SharedRatesClient:
        with self._lock:
            key = len(self._wishes)
            self._wishes[key] = {}
        return SharedRatesClient(self, key)

    def _watch(self, key: int, topics: dict[str, str]) -> None:
        with self._lock:
            if self._wishes.get(key) == topics:
                return
            self._wishes[key] = dict(topics)
            union: dict[str, str] = {}
            for wish in self._wishes.values():
                union.update(wish)
        self._board.watch(union)

    def rate(self, topic: str, window_sec: float = RATE_WINDOW_SEC) -> float | None:
        return self._board.rate(topic, window_sec)

    def latest(self, topic: str) -> tuple[float, object] | None:
        return self._board.latest(topic)

    def heard(self, topic: str, window_sec: float = RATE_WINDOW_SEC) -> bool:
        return self._board.heard(topic, window_sec)

    def watched(self) -> list[str]:
        return self._board.watched()

    def close(self) -> None:
        self._board.close()


class SharedRatesClient:
    """One drawing's view of ``SharedRates``: the RateBoard calls it uses."""

    def __init__(self, shared: SharedRates, key: int) -> None:
        self._shared, self._key = shared, key
        self._wanted: set[str] = set()

    def watch(self, topics: dict[str, str]) -> None:
        self._wanted = set(topics)
        self._shared._watch(self._key, topics)

    def rate(self, topic: str, window_sec: float = RATE_WINDOW_SEC) -> float | None:
        return self._shared.rate(topic, window_sec)

    def latest(self, topic: str) -> tuple[float, object] | None:
        return self._shared.latest(topic)

    def heard(self, topic: str, window_sec: float = RATE_WINDOW_SEC) -> bool:
        return self._shared.heard(topic, window_sec)

    def watched(self) -> list[str]:
        """What this drawing asked for and is measured."""
        return [t for t in self._shared.watched() if t in self._wanted]

    def close(self) -> None:
        self.watch({})


MEASURING = "measuring…"


def rate_text(rate: float | None, heard: bool = False) -> str:
    """'2.0 Hz', 'silent', or '' when not measured; 'measuring…' for no rate yet from a
    topic ``heard`` a moment ago (a rate takes two messages: a talker that just started
    is not silent)."""
    if rate is None:
        return ""
    if rate <= 0:
        return MEASURING if heard else "silent"
    return f"{rate:.1f} Hz" if rate < 100 else f"{rate:.0f} Hz"
