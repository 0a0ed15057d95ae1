"""A subscription the dashboard keeps on one topic: recent messages, count, rate.

Callbacks run on the ROS executor thread; panels read from the viser or UI
thread. The deque and counters are guarded by one lock (single writer: the
subscription callback).
"""

from __future__ import annotations

import threading
import time
from collections import deque
from typing import Any

from rclpy.node import Node
from rclpy.qos import QoSProfile, qos_profile_sensor_data


class TopicTap:
    def __init__(
        self,
        node: Node,
        topic: str,
        msg_type: type,
        *,
        keep: int = 50,
        qos: QoSProfile | int = 10,
    ) -> None:
        self.topic = topic
        self.msg_type = msg_type
        self._node = node
        self._lock = threading.Lock()
        self._recent: deque[tuple[float, Any]] = deque(maxlen=keep)
        self._stamps: deque[float] = deque(maxlen=512)
        self._count = 0
        self._subscription = node.create_subscription(msg_type, topic, self._on_message, qos)

    def _on_message(self, msg: Any) -> None:
        now = time.monotonic()
        with self._lock:
            self._recent.append((time.time(), msg))
            self._stamps.append(now)
            self._count += 1

    @property
    def count(self) -> int:
        with self._lock:
            return self._count

    def recent(self, last: int | None = None) -> list[tuple[float, Any]]:
        with self._lock:
            items = list(self._recent)
        return items[-last:] if last else items

    def rate_hz(self, window_sec: float = 5.0) -> float | None:
        """Mean rate over the last ``window_sec``; None with fewer than two messages."""
        now = time.monotonic()
        with self._lock:
            stamps = [t for t in self._stamps if now - t <= window_sec]
        if len(stamps) < 2:
            return None
        span = stamps[-1] - stamps[0]
        return (len(stamps) - 1) / span if span > 0 else None

    def close(self) -> None:
        self._node.destroy_subscription(self._subscription)


__all__ = ["TopicTap", "qos_profile_sensor_data"]
