"""A dashboard whose ROS layer stops answering is ended by its guard and started again.

The real cause (a Fast DDS 2.14.5 deadlock between two of its own threads,
app/ros/liveness.py) takes minutes of heavy DDS traffic to bring about
(tools/fastdds_deadlock.py does, to study it), far too long for a test. What
it does to the dashboard is quick to cause: a thread blocks for good in native
code holding the GIL, and every other Python thread stops waiting for it. The
dashboard does exactly that on SIGUSR2 when the test asks for it
(``FREEZE_VARIABLE``), so that stands in for the deadlock here; the guard, a
process of its own, is not stopped with it. (SIGSTOP, used before, stops a
thread anywhere, even halfway through building a frame, and faulthandler's
dump then crashed on that frame, before the probe's stack.)

Through ``make run``'s keeper (app/keep_serving.py), with the guard's limit
at 6 s:
- a healthy dashboard lives through three limits untouched (its probes keep
  the guard fed);
- a stopped one is ended within the limit and a few seconds, its log says
  why and holds every thread's stack, and the keeper starts a new one that
  serves the page again;
- Ctrl+C (SIGINT to the process group, as a terminal sends it) then ends it
  all, and no guard is left behind.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import urllib.request

import psutil
import pytest

from app import PROJECT_ROOT
from app.ros.liveness import FREEZE_VARIABLE, GUARD_NAME, LIMIT_VARIABLE
from tests.conftest import ARTIFACTS, free_port, wait_until

pytestmark = [pytest.mark.ros, pytest.mark.timeout(180)]

LIMIT_SEC = 6  # long enough that a loaded machine never starves a healthy probe


def _dashboard_pid(keeper: subprocess.Popen[bytes]) -> int | None:
    """The keeper's child that serves (there is one at a time)."""
    for child in psutil.Process(keeper.pid).children():
        try:
            if "serve" in child.cmdline() and child.status() != psutil.STATUS_ZOMBIE:
                return child.pid
        except psutil.NoSuchProcess:
            continue
    return None


def _guards_of(pid: int) -> list[psutil.Process]:
    found = []
    for proc in psutil.process_iter(["cmdline"]):
        cmdline = proc.info["cmdline"] or []
        if GUARD_NAME in cmdline and str(pid) in cmdline:
            found.append(proc)
    return found


def _page_answers(port: int) -> bool:
    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=5) as reply:
            return reply.status == 200
    except OSError:
        return False


def test_a_dashboard_that_stops_answering_is_ended_and_started_again(ros_env, tmp_path):
    port = free_port()
    log_path = ARTIFACTS / f"liveness-{port}.log"
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    env = {**ros_env, "PYTHONUNBUFFERED": "1", LIMIT_VARIABLE: str(LIMIT_SEC), FREEZE_VARIABLE: "1"}
    argv = ["serve", "--port", str(port), "--progress-dir", str(tmp_path / "progress")]
    with open(log_path, "wb") as log_file:
        keeper = subprocess.Popen(
            [sys.executable, "-m", "app.keep_serving", *argv],
            cwd=PROJECT_ROOT,
            env=env,
            stdout=log_file,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # its own group: SIGINT to it is a terminal's Ctrl+C
        )
    log = lambda: log_path.read_text(errors="replace")  # noqa: E731
    try:
        wait_until(lambda: log().count("is ready") == 1, timeout=60, what="the dashboard")
        first = _dashboard_pid(keeper)
        assert first is not None, log()
        assert len(_guards_of(first)) == 1, "one guard per dashboard"

        time.sleep(3 * LIMIT_SEC)  # fed by its probes, the guard leaves a healthy one alone
        assert psutil.pid_exists(first) and _dashboard_pid(keeper) == first, log()
        assert "stopped answering" not in log()
        assert _page_answers(port)

        os.kill(first, signal.SIGUSR2)  # the GIL held in native code, as in the deadlock
        stopped_at = time.monotonic()
        wait_until(lambda: not psutil.pid_exists(first), timeout=LIMIT_SEC + 15,
                   what="the guard to end the stopped dashboard")  # fmt: skip
        ended_after = time.monotonic() - stopped_at
        text = log()
        assert f"stopped answering for {LIMIT_SEC} s" in text, text
        assert "Fatal Python error: Aborted" in text, "faulthandler's stacks are in the log"
        assert "Thread 0x" in text and "liveness.py" in text, "the probe thread's stack too"
        # The main thread, frozen by the test, is the last one faulthandler writes.
        assert "_hold_the_gil_for_ever" in text, "the dump reached every thread"
        assert ended_after < LIMIT_SEC + 8, f"ended {ended_after:.1f} s after it stopped"

        wait_until(lambda: log().count("is ready") == 2, timeout=60, what="the restart")
        assert "starting it again" in log()
        second = _dashboard_pid(keeper)
        assert second not in (None, first)
        wait_until(lambda: _page_answers(port), timeout=20, what="the page again")
        assert not _guards_of(first), "the ended dashboard's guard left with it"

        os.killpg(keeper.pid, signal.SIGINT)  # Ctrl+C in the terminal
        assert keeper.wait(30) == 0, log()
        assert not psutil.pid_exists(second)
        wait_until(lambda: not _guards_of(second), timeout=10, what="the guard to leave")
    finally:
        if keeper.poll() is None:
            os.killpg(keeper.pid, signal.SIGKILL)
            keeper.wait()
        for pid in filter(None, (locals().get("first"), locals().get("second"))):
            for guard in _guards_of(pid):
                guard.kill()
