"""The stage's code window shows the workspace file a step works on, as it is on disk now."""

from __future__ import annotations

import pytest

from app.learner_ws import folder
from app.learner_ws.folder import LearnerWorkspace
from app.lessons import step_code
from app.lessons.schema import LessonError, _code_list
from tests.course_data import shared_course


@pytest.fixture
def workspace(tmp_path):
    ws = LearnerWorkspace(tmp_path / "ros2_ws")
    folder.configure(ws)
    yield ws
    folder.configure(None)


def _step(lesson_id: str, title: str):
    lesson = next(x for x in shared_course().lessons if x.id == lesson_id)
    return lesson, next(s for s in lesson.steps if s.title == title)


def test_the_no_executable_step_shows_the_learners_setup_py_live(workspace):
    lesson, step = _step("20_workspaces_packages", "'No executable found', and the fix")
    assert step_code.workspace_sources(step) == ("src/py_pubsub/setup.py",)
    assert "not written yet" in step_code.listing(lesson, step)
    setup = workspace.src / "py_pubsub" / "setup.py"
    setup.parent.mkdir(parents=True)
    setup.write_text("entry_points={'console_scripts': ['listner = py_pubsub.sub:main']}\n")
    shown = step_code.listing(lesson, step)
    assert "Your workspace: ~/ros2_ws/src/py_pubsub/setup.py" in shown and "listner" in shown
    assert "talker.py" not in shown  # not the lesson's tutorial node: the learner's file


def test_a_package_xml_is_highlighted_as_xml_and_a_step_without_files_shows_the_lesson_code(
    workspace,
):
    lesson, step = _step("20_workspaces_packages", "Write the publisher and register it")
    assert step_code.workspace_sources(step) == (
        "src/py_pubsub/py_pubsub/publisher_member_function.py",
        "src/py_pubsub/package.xml",
        "src/py_pubsub/setup.py",
    )
    xml = workspace.src / "py_pubsub" / "package.xml"
    xml.parent.mkdir(parents=True)
    xml.write_text("<package><exec_depend>rclpy</exec_depend></package>\n")
    assert "exec_depend" in step_code.listing(lesson, step)
    lesson, build = _step("20_workspaces_packages", "Build it")
    assert step_code.workspace_sources(build) == ()
    assert "nodes/talker.py" in step_code.listing(lesson, build)


def test_a_link_out_of_the_workspace_is_not_followed(workspace, tmp_path):
    lesson, step = _step("20_workspaces_packages", "'No executable found', and the fix")
    secret = tmp_path / "secret.txt"
    secret.write_text("do not show\n")
    setup = workspace.src / "py_pubsub" / "setup.py"
    setup.parent.mkdir(parents=True)
    setup.symlink_to(secret)
    shown = step_code.listing(lesson, step)
    assert "cannot be shown" in shown and "do not show" not in shown


def test_a_step_can_name_its_own_project_files():
    """Lesson 8 walks a .msg, a .srv and an .action: each step shows the one it is about."""
    lesson, service = _step("08_interfaces", "A service: request --- response")
    shown = step_code.listing(lesson, service)
    assert "AddTwoInts.srv" in shown and "DetectedObject.msg" not in shown
    lesson, procedural = _step("04_first_node", "The same node without a class")
    shown = step_code.listing(lesson, procedural)
    assert "minimal_node_procedural.py" in shown and "nodes/minimal_node.py" not in shown


def test_the_launch_lesson_reads_the_launch_file_that_ros2_launch_runs():
    """Lesson 12's first step is about chatter_demo.launch.py, a file the classroom writes
    for `ros2 launch` from the catalog's group: the window shows that very text."""
    lesson, read = _step("12_launch", "Read the launch file")
    assert read.stage == "code"
    shown = step_code.listing(lesson, read)
    assert "tutorial_nodes/launch/chatter_demo.launch.py" in shown
    assert "generate_launch_description" in shown and "listener2" in shown


def test_a_launch_code_entry_must_name_a_catalog_group(tmp_path):
    with pytest.raises(LessonError, match="no launch group 'nonesuch'"):
        _code_list({"code": ["launch/nonesuch.launch.py"]}, "here")
