"""Package grading on bad input: a build that never ends or a folder that is no package
gives a result the learner can read, never a crash (no ROS needed: grading stops first)."""

from __future__ import annotations

import os
import shutil
import time

import pytest

from app.containment.policy import RunPolicy
from app.exercises import package_grading
from app.exercises.grader import Grader
from app.supervisor import Supervisor
from tests.course_data import shared_exercises

EXERCISE = shared_exercises().get("package_doubler")


@pytest.fixture
def grader():
    supervisor = Supervisor(os.environ)
    yield Grader(None, supervisor)  # type: ignore[arg-type]  (no ROS: grading stops before)
    supervisor.shutdown()


def test_a_setup_py_that_loops_forever_is_stopped_and_reported(grader, tmp_path, monkeypatch):
    monkeypatch.setattr(package_grading, "BUILD_SECONDS", 3.0)
    assert EXERCISE.reference_dir is not None
    package = tmp_path / "py_doubler"
    shutil.copytree(EXERCISE.reference_dir, package)
    setup = package / "setup.py"
    setup.write_text("while True:\n    pass\n" + setup.read_text())
    started = time.monotonic()
    report = package_grading.grade_package(grader, EXERCISE, package, tmp_path / "scratch")
    assert time.monotonic() - started < 30
    assert not report.passed and not report.problem
    [result] = report.results
    assert result.name == "colcon build" and not result.passed
    assert "ran longer than 3 s" in result.detail and "loop forever" in result.detail
    assert not any(status.active for status in grader.supervisor.statuses().values())


def test_a_folder_without_package_xml_and_a_served_dashboard_without_leave_are_refused(
    grader, tmp_path
):
    # (A served dashboard that allows learner code builds it contained:
    # tests/sandbox/test_contained_build.py.)
    report = package_grading.grade_package(grader, EXERCISE, tmp_path, tmp_path / "scratch")
    assert not report.passed and "no package.xml" in report.problem
    assert EXERCISE.reference_dir is not None
    refused = RunPolicy(allowed=False, contained=True)
    report = package_grading.grade_package(
        grader, EXERCISE, EXERCISE.reference_dir, tmp_path / "s", policy=refused
    )
    assert "--allow-learner-code" in report.problem
    assert grader.supervisor.statuses() == {}
