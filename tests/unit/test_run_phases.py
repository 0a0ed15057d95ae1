"""tests/run.py's two phases: the suite in workers, then the loaded tests alone."""

from __future__ import annotations

from tests import run


def test_the_loaded_tests_run_after_the_rest_alone():
    first, second = run.pytest_phases(["tests/sim", "--workers", "3", "-x"])
    at = first.index("not (loaded or alone)")
    assert first[at - 1] == "-m" and "--tx" in first
    assert "--max-worker-restart=0" in first  # a dead worker fails the run, never replaced
    assert second[-2:] == ["-m", "loaded or alone"] and "--tx" not in second
    assert "tests/sim" in second and "-x" in second and "--workers" not in second


def test_a_run_that_picks_its_marks_is_one_phase():
    assert len(run.pytest_phases(["-m", "browser"])) == 1
    assert len(run.pytest_phases(["-mros"])) == 1


def test_failed_tests_let_the_next_phase_run_an_interruption_does_not(monkeypatch):
    ran: list[str] = []

    def call(command: list[str]) -> int:
        ran.append(command[0])
        return {"a": 1, "b": 0, "c": 2}[command[0]]

    monkeypatch.setattr(run.subprocess, "call", call)
    assert run.run_phases([["a"], ["b"]], keeper=False) == 1 and ran == ["a", "b"]
    ran.clear()
    assert run.run_phases([["c"], ["b"]], keeper=False) == 2 and ran == ["c"]
    ran.clear()
    monkeypatch.setattr(run.subprocess, "call", lambda command: run.NO_TESTS)
    assert run.run_phases([["x"], ["y"]], keeper=False) == run.NO_TESTS
