"""A child the supervisor starts dies with the dashboard, even one forked as it died."""

from __future__ import annotations

import os
import subprocess
import sys
import time

from app.supervisor import die_with


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
