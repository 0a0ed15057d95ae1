"""Is the dashboard's DDS participant still answering? If not, a guard outside Python ends it.

Fast DDS 2.14.5, the release in the ROS 2 Jazzy wheels, can deadlock two of a
participant's own threads: its discovery thread, removing a remote writer,
waits for the event thread, which waits for the discovery thread's lock
(eProsima/Fast-DDS#6502, seen here once in about 16 test-suite runs). From
then on, every thread that creates a reader or writer in that process blocks
for good inside native code while holding the GIL, and the whole dashboard
freezes: pages, panels, Stop buttons. No Python thread can notice, and only a
new process brings the participant back.

So a thread here creates and destroys a subscription now and then (the path
that blocks), and after each one writes a line to a guard: a bash process in
a session of its own. When no line has come for ``limit`` seconds, the guard
says why on the dashboard's stderr and ends it with SIGABRT (faulthandler then
writes every thread's stack to the log), then SIGKILL. The nodes the dashboard
started end with it (their parent-death signal), progress is saved as it
goes, and ``make run`` and the classroom start the dashboard again: the guard
leaves a mark for them first, since its SIGKILL would read as anyone's
(app/restart_rule.py).
When the dashboard stops or dies, the guard reads the end of its pipe and
leaves quietly.
"""

from __future__ import annotations

import ctypes
import logging
import os
import shutil
import signal
import subprocess
import threading

from rclpy.node import Node
from std_msgs.msg import Empty

from app.restart_rule import MARK_VARIABLE

LIMIT_VARIABLE = "CLASSROOM_LIVENESS_LIMIT_SEC"  # tests set a few seconds
# Tests only: with this set to 1, SIGUSR2 freezes the dashboard as the deadlock does
# (see freeze_on_sigusr2_for_tests).
FREEZE_VARIABLE = "CLASSROOM_LIVENESS_TEST_FREEZE"
# Creating a reader takes milliseconds; a whole minute without one is a hang, even
# on two cores busy with a test suite.
DEFAULT_LIMIT_SEC = 60.0
PROBES_PER_LIMIT = 12  # a probe every 5 s with the default limit
PROBE_TOPIC = "/_classroom_liveness"  # hidden (leading underscore), and nobody publishes on it
GUARD_NAME = "classroom-ros-liveness"  # the guard's $0: what `ps` shows
# $1 the dashboard's pid, $2 the limit in seconds, $3 what to say when it fires, $4 the
# mark to create first (empty: none).
# `read -t` ends with a status above 128 on its time limit, and 1 at the end of
# the pipe (the dashboard stopped or died): only the first is a hang.
_GUARD_SCRIPT = """
while :; do
  read -r -t "$2" _
  status=$?
  [ "$status" -eq 0 ] && continue
  [ "$status" -gt 128 ] || exit 0
  echo "$3" >&2
  [ -z "$4" ] || : 2>/dev/null > "$4"
  kill -ABRT "$1" 2>/dev/null; kill -CONT "$1" 2>/dev/null
  for _ in 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15; do
    sleep 0.2; kill -0 "$1" 2>/dev/null || exit 0
  done
  kill -KILL "$1" 2>/dev/null
  exit 0
done
"""

log = logging.getLogger(__name__)


def limit_from_env() -> float:
    try:
        return max(1.0, float(os.environ.get(LIMIT_VARIABLE) or DEFAULT_LIMIT_SEC))
    except ValueError:
        return DEFAULT_LIMIT_SEC


def start_guard(bash: str, pid: int, limit: float, line: str) -> subprocess.Popen[bytes]:
    """The guard of process ``pid``: fed a line on its stdin at least every ``limit`` s,
    or it says ``line`` and ends ``pid`` (after leaving the restarter's mark, if any)."""
    return subprocess.Popen(
        [
            bash,
            "-c",
            _GUARD_SCRIPT,
            GUARD_NAME,
            str(pid),
            f"{limit:g}",
            line,
            os.environ.get(MARK_VARIABLE, ""),
        ],  # fmt: skip
        stdin=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        start_new_session=True,  # Ctrl+C in the terminal is the dashboard's, not the guard's
    )


class ParticipantLiveness:
    """Probe the participant of ``node`` every ``limit / 12`` s; a guard ends us if it hangs."""

    def __init__(self, node: Node, limit: float | None = None) -> None:
        self._node = node
        self.limit = limit if limit is not None else limit_from_env()
        self._stopping = threading.Event()
        self._guard: subprocess.Popen[bytes] | None = None
        self._thread = threading.Thread(target=self._run, name="ros-liveness", daemon=True)
        self.probes = 0
        self.guard_pid: int | None = None  # while it runs, and after (what `ps` showed)

    def start(self) -> None:
        bash = shutil.which("bash")
        if bash is None:  # every Debian and Ubuntu has it; say so rather than fail
            log.warning("no bash on PATH: a hung DDS participant would not be noticed")
            return
        line = (
            f"[ERROR] this dashboard's ROS participant stopped answering for {self.limit:g} s "
            "(most likely Fast DDS 2.14's deadlock, eProsima/Fast-DDS#6502): ending it with "
            "SIGABRT so that it starts again (`make run` and `classroom` do); progress is kept"
        )
        self._guard = start_guard(bash, os.getpid(), self.limit, line)
        self.guard_pid = self._guard.pid
        self._thread.start()
        if os.environ.get(FREEZE_VARIABLE) == "1":
            freeze_on_sigusr2_for_tests()

    def _run(self) -> None:
        period = self.limit / PROBES_PER_LIMIT
        while True:
            try:
                sub = self._node.create_subscription(Empty, PROBE_TOPIC, _ignore, 1)
                self._node.destroy_subscription(sub)
            except Exception:  # an error, not a hang: never a reason to end the dashboard
                log.exception("the ROS liveness probe failed; it stops, and so does its guard")
                self._release_guard()
                return
            self.probes += 1
            if not self._beat() or self._stopping.wait(period):
                return

    def _beat(self) -> bool:
        guard = self._guard
        if guard is None or guard.stdin is None:
            return False
        try:
            guard.stdin.write(b".\n")
            guard.stdin.flush()
        except (BrokenPipeError, ValueError):  # the guard was ended, or we are stopping
            log.warning("the ROS liveness guard is gone: a hung participant would not be noticed")
            return False
        return True

    def stop(self, timeout: float = 5.0) -> None:
        """Stop probing; the guard sees the end of its pipe and leaves."""
        self._stopping.set()
        if self._thread.is_alive():
            self._thread.join(timeout)
        self._release_guard(timeout)

    def _release_guard(self, timeout: float = 5.0) -> None:
        """Close the guard's pipe: it leaves without ending anything."""
        guard, self._guard = self._guard, None
        if guard is None:
            return
        if guard.stdin is not None:
            guard.stdin.close()
        try:
            guard.wait(timeout)
        except subprocess.TimeoutExpired:
            guard.kill()
            guard.wait()


def freeze_on_sigusr2_for_tests() -> None:
    """Fault injection for tests/faults/test_ros_liveness.py (main thread only): SIGUSR2
    puts the process in the state the deadlock leaves it in.

    The handler blocks in native code and keeps the GIL (ctypes.PyDLL calls do not
    release it, like rclpy's calls into rcl), so every other Python thread stops where it
    waits for the GIL: between two bytecodes or in a call that released it. SIGSTOP stops
    the threads too, but anywhere, even halfway through building a Python frame, and
    faulthandler's dump of all threads then read that frame and crashed (a fresh-clone
    run: "File ???, line 0" and a segmentation fault before the probe's stack)."""
    signal.signal(signal.SIGUSR2, _hold_the_gil_for_ever)


def _hold_the_gil_for_ever(_signum: int, _frame: object) -> None:
    pause = ctypes.PyDLL(None).pause  # returns only when a signal is caught: wait again
    while True:
        pause()


def _ignore(_msg: Empty) -> None:
    """Nobody publishes on the probe topic; rclpy wants a callback all the same."""
