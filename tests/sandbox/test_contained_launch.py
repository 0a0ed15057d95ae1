"""A learner's launch file served to other machines follows the rule of their other code.

It is Python the learner wrote, so it runs through the sandbox launcher
(contained) or, without the teacher's consent, not at all; ours (the
catalog's launch files) run as they are.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from app.containment.policy import RunPolicy, RunRefused
from app.containment.sandbox import sandbox_available
from app.exercises import runner
from app.launch_prefix import LaunchRefused, find_launch_file, launch_program
from tests.course_data import shared_exercises

EXERCISE = shared_exercises().get("launch_pair")


def test_a_learners_launch_file_is_contained_when_served_to_others(tmp_path: Path):
    script = tmp_path / f"{EXERCISE.slug}.py"
    script.write_text(EXERCISE.reference)
    policy = RunPolicy(allowed=True, contained=True, hidden=(tmp_path / "bob",))
    if sandbox_available() is not None:  # this machine cannot contain: refused, never run plain
        with pytest.raises(RunRefused, match="must run contained here, and cannot"):
            runner.program_for(EXERCISE, script, policy)
        return
    program = runner.program_for(EXERCISE, script, policy)
    assert program.argv[1].endswith("contain.py") and program.argv[-1] == str(script)
    assert "--hide" in program.argv and program.after_exit is not None


def test_without_the_teachers_consent_no_launch_file_runs(tmp_path: Path, supervisor):
    script = tmp_path / f"{EXERCISE.slug}.py"
    script.write_text(EXERCISE.reference)
    with pytest.raises(RunRefused, match="--allow-learner-code"):
        runner.start(supervisor, EXERCISE, script, RunPolicy(allowed=False, contained=True))
    assert runner.status(supervisor, EXERCISE) is None
    with pytest.raises(LaunchRefused, match="--allow-learner-code"):
        launch_program("x", "", [str(script)], tmp_path, RunPolicy(allowed=False), trusted=False)
    with pytest.raises(LaunchRefused, match="no rule for learner code"):
        launch_program("x", "", [str(script)], tmp_path, None, trusted=False)


def test_our_launch_files_run_as_they_are_even_when_served(tmp_path: Path):
    path = find_launch_file("turtlesim", "multisim.launch.py")
    program = launch_program(
        "x", "", [str(path)], path.parent, RunPolicy(allowed=False, contained=True), trusted=True
    )
    assert program.argv[1].endswith("ros2launch/__main__.py") and program.after_exit is None
    assert program.env is not None and str(path.parents[3]) in program.env["AMENT_PREFIX_PATH"]
