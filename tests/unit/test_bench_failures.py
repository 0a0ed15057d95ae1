"""A benchmark that cannot produce its figures is a failed row with its reason, and
what a run started is found and ended at its end, even in a session of its own."""

from __future__ import annotations

import os
import subprocess
import sys
import time

from bench import _reaper
from bench.summary import markdown


def test_a_benchmark_without_figures_is_a_failed_row_with_its_reason():
    text = markdown({}, {"echo_hz_load": 301.0}, {"echo_hz_load": "timed out after 300 s"})
    rows = [line for line in text.splitlines() if "echo_hz_load" in line and "|" in line]
    assert rows and all("FAILED" in r and "timed out after 300 s" in r for r in rows)
    assert all(r.rstrip().endswith("**no** |") for r in rows)


def test_figures_from_a_benchmark_that_failed_anyway_are_flagged():
    text = markdown(
        {"idle_cost": {}}, {"idle_cost": 9.0}, {"idle_cost": "left 2 processes running"}
    )
    assert "FAILED despite figures: idle_cost: left 2 processes running" in text


def test_the_run_mark_finds_an_orphan_in_its_own_session_and_ends_it(monkeypatch):
    monkeypatch.setenv(_reaper.MARK, "outer")  # restored after the test
    mark = _reaper.mark_this_run("unit")
    child = subprocess.Popen(
        [sys.executable, "-c", "import time; time.sleep(60)"], start_new_session=True
    )
    try:
        deadline = time.monotonic() + 5
        while child.pid not in [pid for pid, _ in _reaper.leftovers(mark)]:
            assert time.monotonic() < deadline, "the marked child was not found"
            time.sleep(0.05)
        assert os.getpid() not in [pid for pid, _ in _reaper.leftovers(mark)]
        ended = _reaper.end_leftovers(mark, grace=0.2)
        assert any(str(child.pid) in line for line in ended)
        assert child.wait(5) == -9
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
