"""A child the supervisor starts dies with the dashboard, even one forked as it died."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import psutil

from app import PROJECT_ROOT
from app.stop_signals import die_with


def test_a_child_of_a_living_parent_runs():
    done = subprocess.run([sys.executable, "-c", "print('ran')"], preexec_fn=die_with(os.getpid()),
                          capture_output=True, text=True, timeout=30)  # fmt: skip
    assert (done.returncode, done.stdout.strip()) == (0, "ran")


def test_a_child_whose_parent_is_already_gone_ends_before_it_runs():
    """Its parent is not the dashboard that forked it (that one died meanwhile)."""
    started = time.monotonic()
    done = subprocess.run([sys.executable, "-c", "print('ran')"], preexec_fn=die_with(1),
                          capture_output=True, text=True, timeout=30)  # fmt: skip
    assert done.returncode != 0 and "ran" not in done.stdout
    assert time.monotonic() - started < 10


# A dashboard-like parent: stop signals handled (app.stop_signals), a child whose
# moment between fork and exec lasts a second, and the parent killed in that second.
PARENT = """
import os, subprocess, sys, threading, time
from app.stop_signals import die_with, set_on_signals

set_on_signals(threading.Event())
die = die_with(os.getpid())

def slow_preexec():
    die()
    time.sleep(1.0)  # the moment before exec, made long

print("forking", flush=True)
subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"], preexec_fn=slow_preexec)
time.sleep(60)
"""


def test_a_parent_killed_just_before_its_child_execs_still_takes_the_child():
    """The fork has the parent's SIGTERM handler until it execs: the death signal must not
    land there (CI: a learner's program outlived a SIGKILLed dashboard)."""
    parent = subprocess.Popen(
        [sys.executable, "-c", PARENT], stdout=subprocess.PIPE, cwd=PROJECT_ROOT, text=True
    )
    child = None
    try:
        assert parent.stdout is not None and parent.stdout.readline().strip() == "forking"
        deadline = time.monotonic() + 10
        while not (children := psutil.Process(parent.pid).children()):
            assert time.monotonic() < deadline, "the child was never forked"
            time.sleep(0.01)
        child = children[0]
        time.sleep(0.3)  # inside its slow moment, its death signal set
        _kill_and_expect_gone(parent, child, 8.0, "the child")
    finally:
        _end(parent, child)


def _kill_and_expect_gone(
    parent: subprocess.Popen, child: psutil.Process, timeout: float, what: str
) -> None:
    """SIGKILL ``parent`` (nothing of it runs after) and wait for ``child`` to end too."""
    parent.kill()
    parent.wait(10)
    gone, _alive = psutil.wait_procs([child], timeout=timeout)
    assert gone, f"{what} (pid {child.pid}) outlived its parent"


def _end(parent: subprocess.Popen, child: psutil.Process | None) -> None:
    """Whatever happened, neither process outlives the test."""
    parent.kill()
    parent.wait(10)
    if child is not None and child.is_running():
        child.kill()


# A dashboard-like parent whose Supervisor starts a learner's program that shrugs off
# SIGTERM (hostile, or only slow to end), then is killed: nobody is left to follow up.
LEARNER = """
import signal, time
signal.signal(signal.SIGTERM, signal.SIG_IGN)
print("ignoring SIGTERM", flush=True)
time.sleep(60)
"""
DASHBOARD = """
import os, sys, time
from pathlib import Path
from app.supervisor import LearnerProgram, Supervisor

script = Path(sys.argv[1])
supervisor = Supervisor(dict(os.environ))
supervisor.start_program(LearnerProgram("learner", "/learner", (sys.executable, str(script)),
                                        script.parent, names_its_node=False))
deadline = time.monotonic() + 20
while "ignoring SIGTERM" not in "\\n".join(supervisor.output("learner", last=5)):
    assert time.monotonic() < deadline, supervisor.output("learner", last=5)
    time.sleep(0.05)
print("learner", supervisor.status("learner").pid, flush=True)
time.sleep(60)
"""


def test_a_learners_program_that_ignores_sigterm_still_dies_with_a_killed_dashboard(tmp_path):
    script = tmp_path / "stubborn.py"
    script.write_text(LEARNER)
    parent = subprocess.Popen([sys.executable, "-c", DASHBOARD, str(script)],
                              stdout=subprocess.PIPE, cwd=PROJECT_ROOT, text=True)  # fmt: skip
    learner = None
    try:
        assert parent.stdout is not None
        line = parent.stdout.readline().split()
        assert line[:1] == ["learner"], line
        learner = psutil.Process(int(line[1]))
        _kill_and_expect_gone(parent, learner, 5.0, "the learner's program")
    finally:
        _end(parent, learner)
