"""A liveness probe that raises (an error, not a hang) stops probing and lets its guard go.

Ending the dashboard for a Python error would turn a small fault into a lost page,
so the guard must leave instead of firing. The node here is a stand-in that only
raises: no DDS is needed to see what the thread and the guard do.
"""

from __future__ import annotations

import os
import time

import psutil

from app.ros.liveness import ParticipantLiveness


class _RaisingNode:
    def create_subscription(self, *_args: object) -> object:
        raise RuntimeError("context is shut down")

    def destroy_subscription(self, _sub: object) -> None:
        raise AssertionError("never reached")


def test_a_probe_that_raises_lets_the_guard_go_and_the_process_live() -> None:
    liveness = ParticipantLiveness(_RaisingNode(), limit=1.0)  # type: ignore[arg-type]
    liveness.start()
    assert liveness.guard_pid is not None
    deadline = time.monotonic() + 5
    while psutil.pid_exists(liveness.guard_pid) and time.monotonic() < deadline:
        time.sleep(0.05)  # the probe raised at once: its pipe closed, so the guard left
    assert not psutil.pid_exists(liveness.guard_pid)
    time.sleep(1.5)  # past the limit: nobody ends this process
    assert psutil.pid_exists(os.getpid())
    assert liveness.probes == 0
    liveness.stop()
