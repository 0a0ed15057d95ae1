"""Unit 15's lesson kinds on a real workspace: each check passes and fails on real files.

One workspace for the module: `ros2 pkg create` and `colcon build` typed through
the Console's path (real colcon). The checks read the workspace's files and
the Console's `source` state; the walk (test_lessons_walk) shows them passing
on the live graph with the learner's own nodes, this module shows each way
they fail, and what the actions refuse.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from app.containment.policy import RunPolicy
from app.exercises.package_grading import grade_learner_package
from app.learner_ws import build, folder, overlay
from app.learner_ws.folder import LearnerWorkspace, OutsideWorkspace
from app.lessons.kinds import ACTIONS, CHECKS
from app.lessons.registry import FAIL, PASS, WAITING
from app.lessons.schema import Spec
from app.ros.context import CallContext, Limits
from app.ros.errors import Ros2Error
from app.ros.graph import GraphSnapshot
from app.ros2cli import run_text
from app.ros2cli.pkg import setup_workspace
from app.supervisor import Supervisor
from tests.course_data import shared_exercises


@dataclass
class Rt:
    """What these kinds take from the lesson runtime: the supervisor and a graph snapshot."""

    supervisor: Supervisor
    graph: GraphSnapshot = field(default_factory=GraphSnapshot)
    console: object = None


def check(rt: Rt, kind: str, **fields):
    return CHECKS[kind].evaluate(rt, Spec(kind, fields))  # type: ignore[arg-type]


def act(rt: Rt, kind: str, **fields) -> str:
    return ACTIONS[kind].perform(rt, Spec(kind, fields))  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def ws(tmp_path_factory):
    saved, underlay = os.environ.get(overlay.PREFIX_ENV), overlay.underlay()
    workspace = setup_workspace(tmp_path_factory.mktemp("kinds") / "p" / "ada.json", remote=False)
    sup = Supervisor(os.environ)

    def console(text: str) -> int:
        return run_text(CallContext(None, lambda _line: None, Limits(), programs=sup), text)

    try:
        yield workspace, Rt(sup), console
    finally:
        sup.shutdown()
        overlay.forget()
        overlay.set_underlay(underlay)
        folder.configure(None)
        if saved is None:
            os.environ.pop(overlay.PREFIX_ENV, None)
        else:
            os.environ[overlay.PREFIX_ENV] = saved


def test_package_checks_fail_until_created_built_and_sourced_then_pass(ws):
    workspace, rt, console = ws
    assert check(rt, "package_created", package="my_package").state == FAIL
    assert check(rt, "package_built", package="my_package").state == FAIL
    assert "neither built" in check(rt, "package_sourced", package="my_package").reason
    create = "ros2 pkg create --build-type ament_python --node-name my_node my_package"
    assert console(create) == 0
    assert check(rt, "package_created", package="my_package").state == PASS
    wrong = check(rt, "package_created", package="my_package", build_type="ament_cmake")
    assert wrong.state == FAIL and "ament_python, not ament_cmake" in wrong.reason
    assert "not in ~/ros2_ws/install" in check(rt, "package_built", package="my_package").reason

    # While colcon runs, install/ may be half written: the checks wait for it.
    program = build.colcon_program(workspace, ["build"])
    rt.supervisor.start_program(program)
    assert check(rt, "package_built", package="my_package").state == WAITING
    assert check(rt, "workspace_file", path="install/setup.bash").state in (WAITING, PASS)
    rt.supervisor.stop(program.name).result(timeout=20)

    assert console("colcon build") == 0
    assert check(rt, "package_built", package="my_package", executable="my_node").state == PASS
    missing = check(rt, "package_built", package="my_package", executable="listener")
    assert missing.state == FAIL and "console_scripts" in missing.reason
    assert check(rt, "package_built", package="my_package", without="listener").state == PASS
    assert check(rt, "package_built", package="my_package", without="my_node").state == FAIL

    unsourced = check(rt, "package_sourced", package="my_package")
    assert unsourced.state == FAIL and "source install/setup.bash" in unsourced.reason
    assert console("source install/setup.bash") == 0
    assert check(rt, "package_sourced", package="my_package").state == PASS


def test_workspace_file_check_and_the_write_and_edit_actions(ws):
    workspace, rt, _console = ws
    path = "src/notes/hello.py"
    assert check(rt, "workspace_file", path=path).state == FAIL
    assert "Wrote ~/ros2_ws/src/notes/hello.py" in act(
        rt, "workspace_write", path=path, content="x = 'a'\n"
    )
    assert check(rt, "workspace_file", path=path).state == PASS
    # Spaces and quote kinds do not matter; the text does.
    assert check(rt, "workspace_file", path=path, contains='x="a"').state == PASS
    assert check(rt, "workspace_file", path=path, contains="x = 'b'").state == FAIL

    # The learner's own file is kept, unless the step says to replace it.
    (workspace.root / path).write_text("mine = 1\n")
    assert "kept" in act(rt, "workspace_write", path=path, content="x = 'a'\n")
    assert (workspace.root / path).read_text() == "mine = 1\n"
    act(rt, "workspace_write", path=path, content="x = 'a'\n", replace=True)
    assert (workspace.root / path).read_text() == "x = 'a'\n"

    assert act(rt, "workspace_edit", path=path, old="'a'", new="'c'") == (
        "Edited ~/ros2_ws/src/notes/hello.py."
    )
    assert "already" in act(rt, "workspace_edit", path=path, old="'a'", new="'c'")
    with pytest.raises(Ros2Error, match="no longer has the text"):
        act(rt, "workspace_edit", path=path, old="'zzz'", new="'y'")
    with pytest.raises(OutsideWorkspace):
        act(rt, "workspace_write", path="../outside.py", content="x = 1\n")
    with pytest.raises(OutsideWorkspace):
        check(rt, "workspace_file", path="/etc/passwd")
    assert not (workspace.root.parent / "outside.py").exists()


def test_console_and_stop_actions_refuse_what_they_are_not_for(ws):
    _workspace, rt, _console = ws
    with pytest.raises(Ros2Error, match="not a colcon or source line"):
        act(rt, "workspace_command", command="rm -rf ~")
    assert act(rt, "workspace_command", command="colcon build").startswith("Type it in the Console")
    assert act(rt, "stop_own", package="my_package", executable="my_node") == (
        "my_package my_node is not running."
    )
    none = check(rt, "own_node", ros_node="/minimal_publisher")
    assert none.state == FAIL and "none of your own programs runs" in none.reason


def test_without_a_learner_workspace_the_checks_fail_with_a_reason(ws):
    _workspace, rt, _console = ws
    current = folder.current()
    folder.configure(None)
    try:
        result = check(rt, "package_built", package="my_package")
    except Ros2Error as exc:  # LessonRuntime.evaluate turns this into a failed check
        assert "no learner workspace" in str(exc)
    else:
        pytest.fail(f"a check without a workspace gave {result}")
    finally:
        folder.configure(current)


def test_check_button_without_the_package_says_how_to_create_it(ws):
    exercise = shared_exercises().get("package_doubler")
    report = grade_learner_package(None, exercise, Path("/nonexistent"), RunPolicy())  # type: ignore[arg-type]
    assert not report.passed
    assert "no package py_doubler in ~/ros2_ws/src" in report.problem
    assert "ros2 pkg create" in report.problem


def test_a_failed_build_shows_the_learners_lines_not_colcons_internals(tmp_path):
    """One translation for the Console and the grader (app.learner_ws.build.build_errors)."""
    from app.learner_ws.build import build_errors, error_summary

    ws = LearnerWorkspace(tmp_path / "ros2_ws").ensure()
    (ws.src / "adder").mkdir()
    (ws.src / "adder" / "package.xml").write_text("<package><name>py_adder</name></package>")
    colcon_output = [
        "Starting >>> py_adder",
        "--- stderr: py_adder",
        "<string>:10: SyntaxWarning: 'tuple' object is not callable; perhaps you missed a comma?",
        "Traceback (most recent call last):",
        '  File "<string>", line 1, in <module>',
        '  File "/venv/lib/python3.11/site-packages/setuptools/_distutils/core.py", line 267, '
        "in run_setup",
        "    exec(code, g)",
        "    ^^^^^^^^^^^^^",
        '  File "<string>", line 10, in <module>',
        "TypeError: 'tuple' object is not callable",
        "---",
        "Failed   <<< py_adder [0.36s, exited with code 1]",
    ]
    lines = build_errors(colcon_output, ws)
    assert not any("site-packages" in line or "exec(code" in line for line in lines), lines
    assert "TypeError: 'tuple' object is not callable" in lines
    assert "  ~/ros2_ws/src/adder/setup.py, line 10, in <module>" in lines
    assert not any("line 1," in line for line in lines)  # colcon's helper, not setup.py
    assert lines[1].startswith("~/ros2_ws/src/adder/setup.py, line 10: SyntaxWarning")
    [error] = error_summary(colcon_output, ws)
    assert error.line() == (
        "~/ros2_ws/src/adder/setup.py, line 10: TypeError: 'tuple' object is not callable"
    )
    cmake = ["--- stderr: py_adder", "CMake Error at CMakeLists.txt:12 (find_package):",
             "  By not providing \"Findrosidl_default_generators.cmake\"", "---"]  # fmt: skip
    assert build_errors(cmake, ws)[1].startswith(
        "CMake Error at ~/ros2_ws/src/adder/CMakeLists.txt, line 12 (find_package)"
    )
    assert error_summary(cmake, ws)[0].where == "~/ros2_ws/src/adder/CMakeLists.txt, line 12"


def test_check_button_builds_the_package_of_that_name_in_the_learners_src(ws, tmp_path):
    """The Exercise tab's Check: ~/ros2_ws/src/py_adder is found, copied and built."""
    import shutil

    from app.exercises.grader import Grader

    workspace, rt, _console = ws
    exercise = shared_exercises().get("package_adder")
    broken = next(m.path for m in exercise.mistakes if m.path.parent.name == "setup_syntax_error")
    shutil.copytree(broken, workspace.src / "py_adder")
    grader = Grader(None, rt.supervisor)  # type: ignore[arg-type]  (the build fails first)
    report = grade_learner_package(grader, exercise, tmp_path, RunPolicy())
    [result] = report.results
    assert result.name == "colcon build" and not result.passed
    assert "TypeError: 'tuple' object is not callable" in result.detail
    assert (workspace.src / "py_adder" / "setup.py").is_file()  # the learner's copy untouched
    assert not (workspace.src / "py_adder" / "build").exists()
