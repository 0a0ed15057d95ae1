"""The timeline's CPU figure (tests/conftest.py): a test's processes, live and reaped."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import psutil

from tests.conftest import _cpu_figure, _tree_cpu_seconds

BURN = "import time\nend = time.process_time() + {s}\nwhile time.process_time() < end: pass\n"


def test_a_child_that_ran_and_was_reaped_is_counted():
    before = _tree_cpu_seconds()
    subprocess.run([sys.executable, "-c", BURN.format(s=0.5)], check=True)
    after = _tree_cpu_seconds()
    assert before is not None and after is not None
    assert after - before >= 0.45, (before, after)


def test_a_grandchild_still_running_is_counted():
    # A shell whose child burns ("; true" keeps the shell from exec-ing it): the
    # grandchild's time is read while it lives. How much it burns in a wall-clock second
    # depends on the machine's load, so the test waits for the grandchild's own clock,
    # read apart, and compares the tree's figure to it.
    child = subprocess.Popen(
        ["/bin/sh", "-c", f"{sys.executable} -c '{BURN.format(s=30)}'; true"],
        start_new_session=True,
    )
    try:
        shell = psutil.Process(child.pid)
        grandchild = _only_child(shell)
        before, grand_before = _tree_cpu_seconds(), _cpu_of(grandchild)
        assert before is not None
        deadline = time.monotonic() + 60
        while _cpu_of(grandchild) - grand_before < 0.5:
            assert time.monotonic() < deadline, "the grandchild got no CPU for a minute"
            time.sleep(0.05)
        grand_after, after = _cpu_of(grandchild), _tree_cpu_seconds()  # the tree's last
        assert after is not None
        # The tree's figure holds at least the grandchild's growth (less a clock tick).
        assert after - before >= (grand_after - grand_before) - 0.1, (before, after)
    finally:
        os.killpg(child.pid, signal.SIGKILL)  # the shell and the grandchild
        child.wait()


def _only_child(shell: psutil.Process) -> psutil.Process:
    deadline = time.monotonic() + 30
    while not (kids := shell.children()):
        assert time.monotonic() < deadline, "the shell started no child"
        time.sleep(0.02)
    return kids[0]


def _cpu_of(proc: psutil.Process) -> float:
    times = proc.cpu_times()
    return times.user + times.system


def test_a_figure_below_zero_is_said_not_written():
    """A session's last test can see the tree lose a reparented process's seconds."""
    assert _cpu_figure(10.0, 12.5) == " cpu 2.5"
    assert _cpu_figure(None, 3.0) == _cpu_figure(3.0, None) == ""
    text = _cpu_figure(450.0, 9.3)
    assert "unknown" in text and "440.7 s" in text and "-" not in text
