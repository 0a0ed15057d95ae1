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


def _run_summary(monkeypatch, tmp_path, outcomes):
    """bench.summary.main with each benchmark's run replaced by ``outcomes[name]``."""
    from bench import summary

    monkeypatch.setattr(summary, "require_private_netns", lambda _why: None)
    monkeypatch.setattr(summary, "RESULTS", tmp_path / "summary.md")
    monkeypatch.setattr(summary, "ROOT", tmp_path)
    monkeypatch.setattr(summary, "run_one", lambda name, _args: outcomes[name])
    code = summary.main(["--only", *outcomes])
    return code, (tmp_path / "summary.md").read_text()


def test_summary_exits_nonzero_on_a_nan_headline_figure_with_the_benchmarks_reason(
    monkeypatch, tmp_path
):
    from bench.summary import failure_reason

    stdout = "measuring...\nFAILED: dashboard_draw_cpu_percent: the 3D view does not draw it\n{}"
    reason = failure_reason(1, stdout, "Traceback ...\nSomeError: the last stderr line")
    assert reason == "dashboard_draw_cpu_percent: the 3D view does not draw it"
    figures = {"sim_rtf": 1.0, "sim_camera_rate_ratio": 0.95, "dashboard_draw_cpu_percent": None}
    code, text = _run_summary(monkeypatch, tmp_path, {"sim_world": (figures, 9.0, reason)})
    assert code == 1
    row = next(line for line in text.splitlines() if "extra CPU" in line and "MuJoCo" in line)
    assert "FAILED" in row and "the 3D view does not draw it" in row and "**no**" in row


def test_summary_fails_a_nan_figure_even_when_the_benchmark_said_nothing(monkeypatch, tmp_path):
    figures = {"echo_ratio": 1.0, "hz_error_percent": float("nan"), "dashboard_missed_total": 0}
    code, text = _run_summary(monkeypatch, tmp_path, {"echo_hz_load": (figures, 5.0, "")})
    assert code == 1
    row = next(line for line in text.splitlines() if "worst hz error, dashboard |" in line)
    assert "FAILED" in row and "no value for hz_error_percent" in row


def test_summary_exits_zero_when_every_figure_is_there(monkeypatch, tmp_path):
    from bench.summary import ROWS, required_keys

    figures = {key: 1.0 for key in required_keys("idle_cost")}
    figures.update({k: 1.0 for _l, b, key, *_ in ROWS if b == "idle_cost" for k in key.split("|")})
    code, text = _run_summary(monkeypatch, tmp_path, {"idle_cost": (figures, 5.0, "")})
    assert code == 0 and "FAILED" not in text


def test_a_crash_without_failed_lines_is_named_by_its_exception():
    from bench.summary import failure_reason

    assert failure_reason(1, "{}", "Traceback\nValueError: boom") == "exit code 1: ValueError: boom"
    assert failure_reason(0, "all good\n{}", "warning: x") == ""
