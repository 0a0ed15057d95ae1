"""Replaying a bag: its serialized bytes, published again on the bag's own clock.

Nothing is deserialized: rclpy's ``Publisher.publish`` takes the CDR bytes
as they were recorded. Each topic is published with the QoS its publishers
offered (transient-local topics latch again). Timing: message ``i`` goes out
at ``start + (stamp_i - stamp_0) / rate``; the wait sleeps until 0.2 ms
before and spins the rest. Sleeping most of the wait matters on a busy
machine: the scheduler favours a thread that wakes up over one that has been
spinning (measured: p95 lateness 0.01-0.04 ms against 0.007-38 ms when the
last 1.5 ms were spun). ``run`` blocks (a worker thread); ``pause``,
``resume`` and ``progress`` may be called from any thread.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from rclpy.node import Node
from rclpy.publisher import Publisher
from rosbags.interfaces import Connection, ConnectionExtRosbag2

from app.bags.bagfile import READ_ERRORS, first_line, open_bag
from app.bags.errors import BagError
from app.bags.qos import replay_profile
from app.ros.convert import ConversionError, import_type
from app.ros.errors import Cancelled

SPIN_SEC = 0.0002  # the last 0.2 ms of each wait is spun, not slept
MATCH_WAIT_SEC = 1.0  # give subscribers a moment to match before the first message


def parse_remap(rules: list[str]) -> dict[str, str]:
    """['/a:=/b'] -> {'/a': '/b'}, as `ros2 bag play --remap` takes them."""
    remap = {}
    for rule in rules:
        old, sep, new = rule.partition(":=")
        if not sep or not old.strip() or not new.strip():
            raise BagError(f"bad remap rule '{rule}' (expected /from:=/to)")
        remap[old.strip()] = new.strip()
    return remap


@dataclass(frozen=True)
class PlayOptions:
    rate: float = 1.0
    loop: bool = False
    start_offset: float = 0.0  # seconds after the bag's first message
    topics: tuple[str, ...] = ()  # only these (empty: all)
    remap: dict[str, str] = field(default_factory=dict)
    delay: float = 0.0  # seconds to wait before the first message


@dataclass(frozen=True)
class PlayProgress:
    position: float  # seconds into the bag
    duration: float
    published: int
    loops: int
    paused: bool

    @property
    def fraction(self) -> float:
        return min(1.0, self.position / self.duration) if self.duration > 0 else 1.0


class Player:
    """One playback of one bag through publishers on ``node``. Call ``close`` when done."""

    def __init__(self, node: Node, path: Path, options: PlayOptions | None = None) -> None:
        self.options = options = options or PlayOptions()
        if not (options.rate > 0 and math.isfinite(options.rate)):
            raise BagError(f"rate must be a positive number, got {options.rate}")
        if options.start_offset < 0 or options.delay < 0:
            raise BagError("start offset and delay must not be negative")
        self.path = path
        self._node = node
        self._bag = open_bag(path)
        self._reader = self._bag.__enter__()
        self._publishers: dict[int, Publisher] = {}
        self._lock = threading.Lock()
        self._resume = threading.Event()
        self._resume.set()
        self._published = 0
        self._loops = 0
        self._position_ns = 0
        self._closed = False
        self._on_publish: Callable[[int, float, float], None] | None = None
        try:
            self._select(options)
        except BaseException:
            self.close()
            raise
        self.start_ns = self._reader.start_time
        self.duration = max(0, self._reader.duration - 1) / 1e9
        if options.start_offset > self.duration and self._reader.message_count:
            self.close()
            raise BagError(
                f"start offset {options.start_offset:g} s is past the bag's end "
                f"({self.duration:.3f} s)"
            )

    def _select(self, options: PlayOptions) -> None:
        in_bag = {c.topic for c in self._reader.connections}
        unknown = [t for t in options.topics if t not in in_bag]
        if unknown:
            raise BagError(
                f"topic {', '.join(unknown)} is not in the bag (it has {', '.join(sorted(in_bag))})"
            )
        for conn in self._reader.connections:
            if options.topics and conn.topic not in options.topics:
                continue
            try:
                py_type = import_type(conn.msgtype, "msg")
            except ConversionError:
                raise BagError(
                    f"cannot play {conn.topic}: its type {conn.msgtype} is not installed here"
                ) from None
            offered = (
                conn.ext.offered_qos_profiles if isinstance(conn.ext, ConnectionExtRosbag2) else []
            )
            topic = options.remap.get(conn.topic, conn.topic)
            self._publishers[conn.id] = self._node.create_publisher(
                py_type, topic, replay_profile(offered)
            )

    @property
    def topics(self) -> list[str]:
        return sorted({p.topic_name for p in self._publishers.values()})

    # ------------------------------------------------------------ any thread

    def pause(self) -> None:
        self._resume.clear()

    def resume(self) -> None:
        self._resume.set()

    @property
    def paused(self) -> bool:
        return not self._resume.is_set()

    def progress(self) -> PlayProgress:
        with self._lock:
            position = max(0, self._position_ns - self.start_ns) / 1e9
            return PlayProgress(position, self.duration, self._published, self._loops, self.paused)

    # ------------------------------------------------------------ worker thread

    def run(
        self,
        cancel: threading.Event,
        on_loop: Callable[[int], None] | None = None,
        on_publish: Callable[[int, float, float], None] | None = None,
    ) -> PlayProgress:
        """Publish the bag (again and again with loop) until its end or ``cancel``.

        ``on_publish(stamp_ns, target, sent)`` (perf_counter seconds) lets a
        benchmark see how close to its schedule each message went out.
        """
        self._on_publish = on_publish
        opts = self.options
        self._wait_for_subscribers(cancel)
        if opts.delay and cancel.wait(opts.delay):
            raise Cancelled()
        first = self.start_ns + int(opts.start_offset * 1e9)
        connections = [c for c in self._reader.connections if c.id in self._publishers]
        while True:
            self._play_once(connections, first, cancel)
            with self._lock:
                self._loops += 1
            if on_loop:
                on_loop(self._loops)
            if not opts.loop or not self._publishers:
                return self.progress()

    def _play_once(
        self, connections: list[Connection], first: int, cancel: threading.Event
    ) -> None:
        rate = self.options.rate
        origin: int | None = None
        clock0 = 0.0
        try:
            for conn, stamp, data in self._reader.messages(connections=connections, start=first):
                if origin is None:
                    origin, clock0 = stamp, time.perf_counter()
                target = clock0 + (stamp - origin) / 1e9 / rate
                shift = self._wait_until(target, cancel)
                clock0 += shift
                self._publishers[conn.id].publish(data)
                if self._on_publish is not None:
                    self._on_publish(stamp, target + shift, time.perf_counter())
                with self._lock:
                    self._published += 1
                    self._position_ns = stamp
        except READ_ERRORS as exc:
            raise BagError(f"the bag {self.path} is damaged: {first_line(exc)}") from None

    def _wait_until(self, target: float, cancel: threading.Event) -> float:
        """Sleep, then spin, until ``target``; returns how long a pause lasted (to shift by)."""
        paused_for = 0.0
        if not self._resume.is_set():
            began = time.perf_counter()
            while not self._resume.wait(0.1):
                if cancel.is_set():
                    raise Cancelled()
            paused_for = time.perf_counter() - began
            target += paused_for
        remaining = target - time.perf_counter()
        if remaining > SPIN_SEC and cancel.wait(remaining - SPIN_SEC):
            raise Cancelled()
        if cancel.is_set():
            raise Cancelled()
        while time.perf_counter() < target:
            pass
        return paused_for

    def _wait_for_subscribers(self, cancel: threading.Event) -> None:
        """Up to a second for each publisher to meet the subscribers the graph shows on its
        topic (one at least), so the first messages reach them all. Meeting just one was not
        enough: this dashboard's own subscription matches at once, a learner's listener in
        another process a moment later (ci60, one core busy: it missed the first message)."""
        deadline = time.monotonic() + MATCH_WAIT_SEC

        def met(pub: Publisher) -> bool:
            return pub.get_subscription_count() >= max(
                1, self._node.count_subscribers(pub.topic_name)
            )

        while time.monotonic() < deadline:
            if all(met(p) for p in self._publishers.values()):
                return
            if cancel.wait(0.05):
                raise Cancelled()

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        for pub in self._publishers.values():
            self._node.destroy_publisher(pub)
        self._publishers.clear()
        self._bag.__exit__(None, None, None)
