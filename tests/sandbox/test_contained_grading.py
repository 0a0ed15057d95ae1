"""An exercise run contained, as a dashboard serving other machines runs it, is graded
like any other: the sandbox leaves ROS 2 over loopback working (services included)."""

from __future__ import annotations

import pytest

from app.containment.policy import RunPolicy, RunRefused
from app.exercises import runner
from app.exercises.grader import Grader
from tests.course_data import shared_exercises
from tests.sandbox.conftest import Classroom

pytestmark = pytest.mark.ros

EXERCISE = shared_exercises().get("multiply_service")


def test_reference_passes_contained_and_a_wrong_one_fails(classroom: Classroom, probe, supervisor):
    policy = RunPolicy(allowed=True, contained=True, hidden=tuple(classroom.hidden))
    grader = Grader(probe.node, supervisor)
    for code, should_pass in ((EXERCISE.reference, True), (EXERCISE.starter, False)):
        script = classroom.write(code, f"{EXERCISE.slug}.py")
        status = runner.start(supervisor, EXERCISE, script, policy)
        assert status.active
        try:
            report = grader.grade(EXERCISE, script)
        finally:
            runner.stop(supervisor, EXERCISE)
        lines = "\n".join([report.problem, *(r.line() for r in report.results)])
        assert report.passed is should_pass, lines
        assert "contained" not in report.problem


def test_without_the_teachers_consent_nothing_runs(classroom: Classroom, supervisor):
    script = classroom.write(EXERCISE.reference, f"{EXERCISE.slug}.py")
    with pytest.raises(RunRefused, match="--allow-learner-code"):
        runner.start(supervisor, EXERCISE, script, RunPolicy(allowed=False, contained=True))
    assert runner.status(supervisor, EXERCISE) is None
