"""Keep only the newest message and draw it from a worker thread, at most N times a second.

The ROS executor thread only drops the message into a one-slot box (never
blocks, never touches viser). A worker thread wakes on arrival, waits out the
remaining throttle interval, and draws whatever is newest then: older frames
are skipped, so a slow browser never builds a backlog and latency stays low.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Callable
from typing import Generic, TypeVar

log = logging.getLogger(__name__)

M = TypeVar("M")  # what is drawn: a message, or a token that says "look again"


class LatestWorker(Generic[M]):
    def __init__(self, name: str, draw: Callable[[M], None], max_hz: float) -> None:
        self._draw = draw
        self._min_interval = 1.0 / max_hz
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._pending: M | None = None
        self._received = 0
        self._arrivals: deque[float] = deque(maxlen=64)
        self._last_arrival: float | None = None
        self._drawn = 0
        self._thread = threading.Thread(target=self._run, name=f"scene-{name}", daemon=True)
        self._thread.start()

    def offer(self, msg: M) -> None:
        """Called from the ROS executor: O(1), never blocks for long."""
        now = time.monotonic()
        with self._lock:
            self._pending = msg
            self._received += 1
            self._arrivals.append(now)
            self._last_arrival = now
        self._wake.set()

    def poke(self, token: M) -> None:
        """Draw ``token`` as soon as the throttle allows, not counted as a message: the
        layer's own "look again" (the 3D view's empty-scene hint reads the count)."""
        with self._lock:
            self._pending = token
        self._wake.set()

    def reset(self) -> None:
        """Forget counters and any pending message (a new topic was picked)."""
        with self._lock:
            self._pending = None
            self._received = 0
            self._drawn = 0
            self._arrivals.clear()
            self._last_arrival = None

    def stats(self) -> tuple[int, int, float | None, float | None]:
        """(received, drawn, rate in Hz over the recent arrivals, seconds since the last one)."""
        now = time.monotonic()
        with self._lock:
            arrivals = list(self._arrivals)
            received, drawn, last = self._received, self._drawn, self._last_arrival
        recent = [t for t in arrivals if now - t < 5.0]
        rate = None
        if len(recent) >= 2 and recent[-1] > recent[0]:
            rate = (len(recent) - 1) / (recent[-1] - recent[0])
        return received, drawn, rate, (now - last) if last is not None else None

    def _run(self) -> None:
        last_draw = 0.0
        while not self._stop.is_set():
            # Everything that gives work sets the wake, and so does stop(): no timeout
            # (a dozen such threads waking twice a second cost each dashboard of a class of 20
            # about 0.4 % of a core: bench/results/findings.md).
            self._wake.wait()
            self._wake.clear()
            wait = last_draw + self._min_interval - time.monotonic()
            if wait > 0 and self._stop.wait(wait):
                break
            with self._lock:
                msg, self._pending = self._pending, None
            if msg is None:
                continue
            last_draw = time.monotonic()
            try:
                self._draw(msg)
            except Exception:  # a bad message must not kill the worker
                log.exception("drawing a message failed")
            with self._lock:
                self._drawn += 1

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        self._thread.join(timeout=2.0)
