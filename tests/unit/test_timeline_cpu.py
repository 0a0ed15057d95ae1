"""The timeline's CPU figure (tests/conftest.py): a test's processes, live and reaped."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

from tests.conftest import _tree_cpu_seconds

BURN = "import time\nend = time.process_time() + {s}\nwhile time.process_time() < end: pass\n"


def test_a_child_that_ran_and_was_reaped_is_counted():
    before = _tree_cpu_seconds()
    subprocess.run([sys.executable, "-c", BURN.format(s=0.5)], check=True)
    after = _tree_cpu_seconds()
    assert before is not None and after is not None
    assert after - before >= 0.45, (before, after)


def test_a_grandchild_still_running_is_counted():
    # A shell whose child burns: the grandchild's time is read while it lives.
    child = subprocess.Popen(
        ["/bin/sh", "-c", f"{sys.executable} -c '{BURN.format(s=5)}'"], start_new_session=True
    )
    try:
        before = _tree_cpu_seconds()
        assert before is not None
        time.sleep(1.0)
        after = _tree_cpu_seconds()
        assert after is not None and after - before >= 0.3, (before, after)
    finally:
        os.killpg(child.pid, signal.SIGKILL)  # the shell and the grandchild
        child.wait()
