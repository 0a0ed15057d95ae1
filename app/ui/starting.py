"""Nodes the learner has just asked to start, so the stage can show the click at once.

Starting a node is a real process start (a fork, Python, rclpy) and ROS then
needs discovery before any tool lists the node: seconds, on a busy machine.
The stage draws a node the moment its Start is clicked, marked 'starting…';
this remembers the request until the supervisor has the process (then its
state says 'starting' until the graph lists the node), the start fails, or
``KEEP_SEC`` passes.
"""

from __future__ import annotations

import threading
import time

KEEP_SEC = 10.0


class StartRequests:
    """Catalog names with the wall time of their Start click; any thread."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._asked: dict[str, float] = {}

    def asked(self, name: str) -> None:
        with self._lock:
            self._asked[name] = time.time()

    def done(self, name: str) -> None:
        """The start ended (the supervisor has the process, or it failed)."""
        with self._lock:
            self._asked.pop(name, None)

    def pending(self) -> dict[str, float]:
        now = time.time()
        with self._lock:
            self._asked = {n: t for n, t in self._asked.items() if now - t < KEEP_SEC}
            return dict(self._asked)
