"""A dashboard its ROS guard ended starts again, however the end came; others stay ended.

The guard (app/ros/liveness.py) aborts a dashboard that stopped answering and
kills it when the abort has not ended it within a few seconds. The restarters
waited for SIGABRT alone, so they took that SIGKILL for a deliberate one and
left the dashboard ended (most likely what a rehearsal's classroom met at load
14: its learner was never restarted). Here a process that ignores SIGABRT
stands in for an abort too slow to finish, and a real guard ends it (no DDS:
the guard is a bash process fed on its stdin).
"""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys

from app.restart_rule import MARK_VARIABLE, GuardMark, ended_for_a_restart
from app.ros.liveness import start_guard

_ABORT_IGNORED = (
    "import signal, sys, time\n"
    "signal.signal(signal.SIGABRT, signal.SIG_IGN)\n"
    "print('ready', flush=True)\n"
    "time.sleep(60)\n"
)


def _guarded_end(monkeypatch, mark_env: str) -> int:
    """How a process whose abort never ends it ends, once its unfed guard fires."""
    monkeypatch.setenv(MARK_VARIABLE, mark_env)
    victim = subprocess.Popen(
        [sys.executable, "-c", _ABORT_IGNORED], stdout=subprocess.PIPE, text=True
    )
    guard = None
    try:
        assert victim.stdout is not None and victim.stdout.readline() == "ready\n"
        bash = shutil.which("bash")
        assert bash is not None
        guard = start_guard(bash, victim.pid, 1.0, "test: the guard fires")
        return victim.wait(timeout=30)
    finally:
        victim.kill()
        victim.wait()
        if guard is not None:
            guard.kill()
            guard.wait()


def test_a_dashboard_the_guard_had_to_kill_is_started_again(monkeypatch, tmp_path):
    mark = GuardMark(tmp_path, "learner2")
    code = _guarded_end(monkeypatch, str(mark.path))
    assert code == -signal.SIGKILL  # the abort did not end it: the guard's SIGKILL did
    assert mark.fired()
    why = ended_for_a_restart(code, mark)
    assert why is not None and "guard ended it" in why


def test_without_the_mark_the_same_kill_reads_as_anyones(monkeypatch, tmp_path):
    """What the classroom did before the mark: a SIGKILL left the dashboard ended."""
    mark = GuardMark(tmp_path, "learner2")
    code = _guarded_end(monkeypatch, "")
    assert code == -signal.SIGKILL and not mark.fired()
    assert ended_for_a_restart(code, mark) is None


def test_which_ends_restart_without_a_guard(tmp_path):
    mark = GuardMark(tmp_path, "learner1")
    assert "SIGABRT" in (ended_for_a_restart(-signal.SIGABRT, mark) or "")  # a native crash
    for code in (0, 1, -signal.SIGTERM, -signal.SIGINT, -signal.SIGKILL):
        assert ended_for_a_restart(code, mark) is None, code  # asked for, or an error at start


def test_a_mark_from_the_last_run_is_cleared_at_the_next_start(tmp_path):
    mark = GuardMark(tmp_path, "learner1")
    mark.path.write_text("")
    assert mark.fired()
    again = GuardMark(tmp_path, "learner1")  # the restarter's next start
    assert not again.fired() and ended_for_a_restart(-signal.SIGKILL, again) is None
