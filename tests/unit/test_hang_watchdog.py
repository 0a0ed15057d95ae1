"""tests/hang_watchdog.py: a process stuck in native code ends, and says where it was."""

from __future__ import annotations

import subprocess
import sys
import time

from app import PROJECT_ROOT
from tests.hang_watchdog import MARGIN_SEC, hangs_in, limit_for, new_text

# A thread that waits for a lock it already holds, inside libc, as Fast DDS's threads did in
# ci119: no signal handler of Python's runs in it, so pytest-timeout could not end it.
STUCK = """
import ctypes, sys
from tests.hang_watchdog import armed

def wait_for_a_lock_held_already():
    libc = ctypes.CDLL(None)
    mutex = ctypes.create_string_buffer(64)  # a pthread_mutex_t, zeroed: the default kind
    libc.pthread_mutex_lock(mutex)
    libc.pthread_mutex_lock(mutex)

with open(sys.argv[1], "a") as log, armed(1.0, log):
    wait_for_a_lock_held_already()
"""


def test_a_process_stuck_in_native_code_ends_with_its_stacks(tmp_path):
    log = tmp_path / "timeline.txt"
    log.write_text("10:00:00 start tests/x.py::test_stuck load 1.0\n")
    before = log.stat().st_size
    started = time.monotonic()
    ended = subprocess.run(
        [sys.executable, "-c", STUCK, str(log)], cwd=PROJECT_ROOT, timeout=60, check=False
    )
    took = time.monotonic() - started
    assert ended.returncode == 1, ended
    assert took < 30, f"ended after {took:.1f} s, armed for 1 s"
    dumps = hangs_in(new_text(log, before))
    assert len(dumps) == 1, log.read_text()
    assert "wait_for_a_lock_held_already" in dumps[0], dumps[0]


def test_a_dump_ends_at_the_next_timeline_line_and_old_text_is_skipped(tmp_path):
    text = (
        "10:00:00 start a load 1\n"
        'Timeout (0:05:00)!\nThread 0x1 (most recent call first):\n  File "x.py", line 3 in f\n'
        "10:05:01 start b load 1\n"
    )
    assert hangs_in(text) == [
        'Timeout (0:05:00)!\nThread 0x1 (most recent call first):\n  File "x.py", line 3 in f'
    ]
    log = tmp_path / "timeline.txt"
    log.write_text(text)
    assert hangs_in(new_text(log, len(text.encode()))) == []
    assert new_text(tmp_path / "missing.txt", 0) == ""


def test_the_limit_is_the_tests_own_timeout_and_a_margin():
    assert limit_for(180.0) == 180.0 + MARGIN_SEC
    assert limit_for(None) == 0.0
