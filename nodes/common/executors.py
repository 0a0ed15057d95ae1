"""A MultiThreadedExecutor that does not spin on callbacks still queued for a worker.

rclpy 7.1.6 (the newest Jazzy wheel) yields a callback again while it waits in
the thread pool for a free worker: the spinning thread submits it over and
over, holds the GIL while doing so, and the workers barely get to run (rclpy
issues #1223 and #1452, fixed upstream after the wheel was built). A node that
blocks in one callback while messages keep arriving, such as the tf2 time
tutorials' listener waiting 50 ms for a transform, then burns a whole core and
its /tf subscription falls a second behind. This executor submits each
callback once and, while it is still queued, lets the workers run instead.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from rclpy.executors import (
    ConditionReachedException,
    ExternalShutdownException,
    MultiThreadedExecutor,
    ShutdownException,
    TimeoutException,
)

# How long the spinning thread steps aside when it meets a callback still queued.
_QUEUED_PAUSE_S = 0.002


class SteadyMultiThreadedExecutor(MultiThreadedExecutor):
    """rclpy's MultiThreadedExecutor, each ready callback handed to the pool once."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self._queued: dict[object, threading.Event] = {}
        self._queued_lock = threading.Lock()

    def _spin_once_impl(
        self, timeout_sec=None, wait_condition: Callable[[], bool] = lambda: False
    ) -> None:
        try:
            handler = self.wait_for_ready_callbacks(timeout_sec, None, wait_condition)[0]
        except (
            ExternalShutdownException,
            ShutdownException,
            TimeoutException,
            ConditionReachedException,
        ):
            return
        with self._queued_lock:
            started = self._queued.get(handler)
            if started is None:
                started = self._queued[handler] = threading.Event()
                first_time = True
            else:
                first_time = False
        if not first_time:  # still waiting for a worker: let one take it
            started.wait(_QUEUED_PAUSE_S)
            return

        def run() -> None:
            started.set()
            try:
                handler()
            finally:
                with self._queued_lock:
                    self._queued.pop(handler, None)

        self._executor.submit(run)
        self._futures.append(handler)
        for future in self._futures[:]:
            if future.done():
                self._futures.remove(future)
                future.result()  # raise any exceptions, as rclpy's own does
