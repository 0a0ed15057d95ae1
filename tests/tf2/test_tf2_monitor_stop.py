"""tf2_monitor ends quietly whenever it is stopped: a SIGTERM that lands after its
spinning thread is made but before it has started (seen once on a loaded machine,
test_sigterm_stops) used to end in "cannot join thread before it is started"."""

from __future__ import annotations

import subprocess
import sys

import pytest

pytestmark = pytest.mark.ros  # the monitor joins the test's private DDS domain

# The signal, landing exactly there: the spinner's start raises what SIGTERM raises.
STOPPED_BEFORE_THE_SPINNER_STARTS = """
import sys, threading
from tf2_ros.tools import tf2_monitor

start = threading.Thread.start

def start_or_stop(thread):
    if getattr(getattr(thread, "_target", None), "__name__", "") == "spin":
        raise KeyboardInterrupt
    start(thread)

threading.Thread.start = start_or_stop
sys.exit(tf2_monitor.main(["tf2_monitor"]))
"""


def test_a_stop_before_the_spinner_starts_ends_quietly(ros_env):
    done = subprocess.run(
        [sys.executable, "-c", STOPPED_BEFORE_THE_SPINNER_STARTS],
        env=ros_env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr, done.stderr
