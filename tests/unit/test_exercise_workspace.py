"""The exercise workspace, lint, crash reading and the editor's file routes (no ROS)."""

from __future__ import annotations

from pathlib import Path

import pytest

from app.exercises import runner
from app.exercises.editor_server import PREFIX, _file_for
from app.exercises.lint import lint, refuses_to_run
from app.exercises.workspace import CodeTooLong, Workspace
from app.lessons.progress import ProgressStore
from tests.conftest import run_cli
from tests.course_data import shared_exercises

EXERCISE = shared_exercises().get("multiply_service")


@pytest.fixture
def workspace(tmp_path) -> Workspace:
    return Workspace(ProgressStore("ada", tmp_path / "progress"), tmp_path / "scratch")


def test_code_starts_as_the_starter_and_survives_a_new_workspace(workspace, tmp_path):
    assert workspace.code(EXERCISE) == EXERCISE.starter
    workspace.save(EXERCISE, "print('mine')\n")
    again = Workspace(ProgressStore("ada", tmp_path / "progress"), tmp_path / "scratch")
    assert again.code(EXERCISE) == "print('mine')\n"
    assert (tmp_path / "progress" / "ada.code" / "multiply_service.py").stat().st_mode & 0o077 == 0


def test_reset_diff_and_the_copy_that_runs(workspace):
    workspace.save(EXERCISE, EXERCISE.starter.replace("TODO 2", "DONE 2"))
    diff = workspace.diff(EXERCISE)
    assert "-        # TODO 2" in diff and "+        # DONE 2" in diff
    script = workspace.script_for_run(EXERCISE)
    assert script.parent == workspace.scratch and "DONE 2" in script.read_text()
    assert workspace.reset(EXERCISE) == EXERCISE.starter
    assert workspace.diff(EXERCISE) == ""


def test_a_pasted_monster_is_refused(workspace):
    with pytest.raises(CodeTooLong):
        workspace.save(EXERCISE, "x = 1\n" * 100_000)


def test_attempts_time_and_when_the_solution_may_show(workspace):
    workspace.save(EXERCISE, "x = 1\n")
    for _ in range(EXERCISE.reveal_after - 1):
        workspace.record_check(EXERCISE, passed=False)
    assert not workspace.may_see_solution(EXERCISE)
    assert workspace.may_see_solution(EXERCISE, reveal_after=1)  # the teacher's number wins
    record = workspace.record_check(EXERCISE, passed=True, seed=4242)
    assert record["attempts"] == EXERCISE.reveal_after
    assert record["seconds_to_pass"] >= 0 and record["passed_seed"] == 4242
    # A later pass keeps the first one's seed, as it keeps the first one's time.
    assert workspace.record_check(EXERCISE, passed=True, seed=7)["passed_seed"] == 4242
    assert workspace.passed(EXERCISE) and workspace.may_see_solution(EXERCISE)


def test_lint_lists_problems_by_line_and_refuses_only_syntax_errors():
    problems = lint("import os\n\nprint(undefined_name)\n")
    assert [(p.line, p.fatal) for p in problems] == [(1, False), (3, False)]
    assert "undefined name 'undefined_name'" in problems[1].text()
    assert not refuses_to_run(problems)
    broken = lint("def f(:\n    pass\n")
    assert refuses_to_run(broken) and broken[0].line == 1


def test_a_traceback_is_pointed_at_the_learners_line(tmp_path):
    script = tmp_path / "mine.py"
    source = "import rclpy\n\ndef main():\n    x = 1 / 0\n\nmain()\n"
    lines = [
        "[INFO] starting",
        "Traceback (most recent call last):",
        f'  File "{script}", line 6, in <module>',
        "    main()",
        f'  File "{script}", line 4, in main',
        "    x = 1 / 0",
        "ZeroDivisionError: division by zero",
    ]
    crash = runner.last_crash(lines, script, source)
    assert crash is not None
    assert crash.line == 4 and crash.code.strip() == "x = 1 / 0"
    assert crash.describe() == "line 4: x = 1 / 0\nZeroDivisionError: division by zero"
    assert runner.last_crash(["all fine"], script, source) is None


@pytest.mark.parametrize(
    "path",
    [
        PREFIX + "../../app/access.py",
        PREFIX + "ace/../../../editor_server.py",
        PREFIX + "ace/../package.json",
        PREFIX + "node_modules/ace-builds/package.json",
        PREFIX + "ace/.hidden.js",
        PREFIX + "package.json",
    ],
)
def test_the_editor_routes_serve_only_the_editor(path):
    assert _file_for(path) is None


def test_the_editor_routes_serve_the_page_and_ace():
    page = _file_for(PREFIX + "editor.html")
    assert page is not None and page.is_file()
    ace = _file_for(PREFIX + "ace/ace.js")
    assert ace is not None and ace.is_file(), "run `make setup`: the editor is installed from npm"


def _cli(*args: str) -> tuple[int, str, str]:
    done = run_cli(*args)
    return done.returncode, done.stdout, done.stderr


def test_exercise_cli_list_starter_solution_and_errors():
    code, out, _err = _cli("exercise", "list")
    assert code == 0 and any(line.startswith("multiply_service ") for line in out.splitlines())
    code, out, _err = _cli("exercise", "starter", "multiply_service")
    assert code == 0 and out == EXERCISE.starter
    code, out, _err = _cli("exercise", "solution", "multiply_service")
    assert code == 0 and out == EXERCISE.reference
    code, _out, err = _cli("exercise", "starter", "no_such_thing")
    assert code == 2 and "no exercise 'no_such_thing'" in err and "Traceback" not in err
    code, _out, err = _cli("exercise", "check", "multiply_service")
    assert code == 2 and "needs the file" in err


def test_exercise_check_refuses_a_syntax_error_without_running(tmp_path: Path):
    bad = tmp_path / "bad.py"
    bad.write_text("def broken(:\n")
    code, out, _err = _cli("exercise", "check", "multiply_service", str(bad))
    assert code == 1 and "syntax error" in out and "not run" in out
