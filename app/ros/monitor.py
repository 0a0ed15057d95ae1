"""One raw subscription behind echo, hz, bw, rates and lesson checks.

``TopicMonitor`` subscribes raw (serialized bytes), so sizes are known for
bandwidth and messages are deserialized only when someone looks at them.
The subscription callback (executor thread) is its single writer; readers on
any other thread take its lock and get copies.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from rclpy.node import Node
from rclpy.qos import QoSProfile
from rclpy.serialization import deserialize_message

from app.ros.qos import matching_qos


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


class TopicMonitor:
    """One raw subscription: arrival stamps, sizes, and the last few messages.

    The subscription callback (executor thread) is the single writer; readers
    on other threads take the lock.
    """

    def __init__(
        self,
        node: Node,
        topic: str,
        msg_type: type,
        *,
        window: int = 10_000,
        keep: int = 100,
        qos: QoSProfile | int | None = None,
    ) -> None:
        # qos: a profile, a depth (reliable, volatile), or None to match the
        # topic's current publishers as `ros2 topic echo` does.
        self.topic = topic
        self.msg_type = msg_type
        self._node = node
        self._cond = threading.Condition()
        self._stamps: deque[float] = deque(maxlen=window)
        self._sizes: deque[tuple[float, int]] = deque(maxlen=window)
        self._recent: deque[tuple[float, bytes]] = deque(maxlen=keep)
        self.count = 0
        self._sub = node.create_subscription(
            msg_type,
            topic,
            self._on_message,
            matching_qos(node, topic) if qos is None else qos,
            raw=True,
        )

    def _on_message(self, data: bytes) -> None:
        now = time.monotonic()
        with self._cond:
            self._stamps.append(now)
            self._sizes.append((now, len(data)))
            self._recent.append((time.time(), data))
            self.count += 1
            self._cond.notify_all()

    def wait_for_count(self, count: int, timeout: float) -> bool:
        """Block (not the executor thread) until ``count`` messages arrived in total."""
        with self._cond:
            return self._cond.wait_for(lambda: self.count >= count, timeout)

    def message(self, index_from_end: int = 1) -> tuple[float, Any] | None:
        with self._cond:
            if len(self._recent) < index_from_end:
                return None
            stamp, data = self._recent[-index_from_end]
        return stamp, deserialize_message(data, self.msg_type)

    def recent(self, last: int | None = None) -> list[tuple[float, Any]]:
        """The newest ``last`` kept messages (all kept ones for None), oldest first."""
        with self._cond:
            raw = list(self._recent)
        if last is not None:
            raw = raw[-last:] if last > 0 else []
        return [(stamp, deserialize_message(data, self.msg_type)) for stamp, data in raw]

    def newest(self) -> Iterator[tuple[float, Any]]:
        """Kept messages newest first, each deserialised only when reached."""
        with self._cond:
            raw = list(self._recent)
        for stamp, data in reversed(raw):
            yield stamp, deserialize_message(data, self.msg_type)

    def rate_hz(self, window_sec: float = 5.0) -> float | None:
        """Mean rate over the last ``window_sec``; None with fewer than two messages."""
        stats = self.rate(window_sec)
        return stats.rate if stats else None

    def messages_since(self, count_before: int) -> list[tuple[float, Any]]:
        """Messages that arrived after the total count was ``count_before`` (as kept)."""
        with self._cond:
            fresh = min(self.count - count_before, len(self._recent))
            raw = list(self._recent)[len(self._recent) - fresh :] if fresh > 0 else []
        return [(stamp, deserialize_message(data, self.msg_type)) for stamp, data in raw]

    def rate(self, window_sec: float | None = None) -> RateStats | None:
        with self._cond:
            stamps = list(self._stamps)
        if window_sec is not None:
            now = time.monotonic()
            stamps = [s for s in stamps if now - s <= window_sec]
        if len(stamps) < 2:
            return None
        periods = [b - a for a, b in zip(stamps, stamps[1:], strict=False)]
        mean = (stamps[-1] - stamps[0]) / len(periods)
        if mean <= 0:
            return None
        std = math.sqrt(sum((p - mean) ** 2 for p in periods) / len(periods))
        return RateStats(1.0 / mean, min(periods), max(periods), std, len(stamps))

    def bandwidth(self, window_sec: float | None = None) -> BandwidthStats | None:
        with self._cond:
            sizes = list(self._sizes)
        if window_sec is not None:
            now = time.monotonic()
            sizes = [(t, s) for t, s in sizes if now - t <= window_sec]
        if len(sizes) < 2:
            return None
        span = sizes[-1][0] - sizes[0][0]
        values = [s for _t, s in sizes]
        if span <= 0:
            return None
        return BandwidthStats(
            sum(values[1:]) / span, len(values), sum(values) / len(values), min(values), max(values)
        )

    def close(self) -> None:
        self._node.destroy_subscription(self._sub)
