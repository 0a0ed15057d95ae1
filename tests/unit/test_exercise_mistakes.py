"""Which recorded mistake a failed grading matches (app/exercises/mistakes.py); where it stays."""

from __future__ import annotations

import pytest

from app.exercises.mistakes import matched_mistake
from app.exercises.report import Report, Result
from app.exercises.workspace import Workspace
from app.lessons.progress import ProgressStore
from tests.course_data import shared_exercises

BOOK = shared_exercises()
WALL_STOP = BOOK.get("wall_stop")  # mistakes: front_is_index_zero, publish_on_change
PACKAGE = BOOK.get("package_adder")  # mistakes are package folders: wrong_module/py_adder


def _report(*results: Result, problem: str = "") -> Report:
    return Report("wall_stop", list(results), problem=problem)


RAN = Result("node running /wall_stop", True, "it runs")


def test_a_failure_is_named_by_the_recorded_mistake_whose_words_it_contains():
    closer = Result("stop before the wall", False, "trial 2: came closer than the bound (0.21 m)")
    assert matched_mistake(WALL_STOP, _report(RAN, closer)) == "front_is_index_zero"
    never = Result("stop before the wall", False, "trial 1: did not come within 0.6 m")
    assert matched_mistake(WALL_STOP, _report(RAN, never)) == "publish_on_change"


def test_the_first_recorded_mistake_wins_whichever_result_says_it():
    never = Result("stop before the wall", False, "did not come within 0.6 m")
    closer = Result("second trial", False, "closer than the bound")
    # front_is_index_zero is listed first in the exercise, so it names the failure.
    assert matched_mistake(WALL_STOP, _report(never, closer)) == "front_is_index_zero"


def test_a_failure_no_mistake_explains_keeps_the_first_failed_results_name():
    odd = Result("stop before the wall", False, "no ground truth arrived during the trial")
    later = Result("log of your node contains 'stop'", False, "nothing logged")
    assert matched_mistake(WALL_STOP, _report(RAN, odd, later)) == "stop before the wall"


def test_a_pass_or_a_grading_with_nothing_failed_names_no_mistake():
    assert matched_mistake(WALL_STOP, _report(RAN)) == ""
    # Not graded (no results): nothing failed, so no mistake either.
    assert matched_mistake(WALL_STOP, _report(problem="syntax error on line 3")) == ""


def test_a_package_exercises_mistake_is_named_by_its_folder_not_the_package():
    [wrong_module] = [m for m in PACKAGE.mistakes if m.path.parent.name == "wrong_module"]
    failed = Result(
        "ros2 run py_adder add_server", False, f"ModuleNotFoundError: {wrong_module.reason}"
    )
    assert matched_mistake(PACKAGE, Report("package_adder", [failed])) == "wrong_module"


@pytest.fixture
def workspace(tmp_path) -> Workspace:
    return Workspace(ProgressStore("ada", tmp_path / "progress"), tmp_path / "scratch")


def test_the_last_mistake_is_kept_with_the_progress_and_cleared_by_a_pass(workspace, tmp_path):
    workspace.record_check(WALL_STOP, passed=False, mistake="publish_on_change")
    record = workspace.record_check(WALL_STOP, passed=False, mistake="front_is_index_zero")
    assert record["last_mistake"] == "front_is_index_zero" and record["failed_checks"] == 2
    again = ProgressStore("ada", tmp_path / "progress")  # a restarted dashboard still knows it
    assert again.exercise("wall_stop")["last_mistake"] == "front_is_index_zero"
    record = workspace.record_check(WALL_STOP, passed=True)
    assert "last_mistake" not in record and "passed_at" in record
    # A failure that named nothing (an older caller) leaves no stale mistake behind.
    workspace.record_check(WALL_STOP, passed=False, mistake="publish_on_change")
    assert "last_mistake" not in workspace.record_check(WALL_STOP, passed=False)
