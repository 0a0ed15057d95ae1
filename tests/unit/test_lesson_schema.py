"""Lesson files: the real course loads cleanly; each corrupted field gives a clear error."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

from app.lessons.schema import LESSONS_DIR, LessonError, load_course, load_lesson
from tests.course_data import shared_course


def test_the_course_loads_without_errors():
    course = shared_course()
    assert course.errors == ()
    assert len(course.lessons) >= 2
    units = [lesson.unit for lesson in course.lessons]
    assert units == sorted(units)


def _dump(data: dict, path: Path) -> None:
    """Minimal TOML writer for the shapes lesson files use."""

    def value(v) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (int, float)):
            return repr(v)
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{" + ", ".join(f'"{k}" = {value(x)}' for k, x in v.items()) + "}"
        raise TypeError(type(v))

    path.write_text("".join(f'"{k}" = {value(v)}\n' for k, v in data.items()))


@pytest.fixture
def lesson_copy(tmp_path) -> tuple[Path, dict]:
    source = LESSONS_DIR / sorted(p.name for p in LESSONS_DIR.iterdir() if p.is_dir())[0]
    target = tmp_path / source.name
    shutil.copytree(source, target)
    return target, tomllib.loads((target / "lesson.toml").read_text())


TOP_LEVEL = ["title", "summary", "goals", "steps"]


@pytest.mark.parametrize("field", TOP_LEVEL)
@pytest.mark.parametrize("damage", ["missing", "wrong_type"])
def test_each_top_level_field_corrupted_names_file_and_field(lesson_copy, field, damage):
    directory, data = lesson_copy
    if damage == "missing":
        del data[field]
    else:
        data[field] = {"title": 3, "summary": [], "goals": 5, "steps": "x"}[field]
    _dump(data, directory / "lesson.toml")
    with pytest.raises(LessonError) as error:
        load_lesson(directory)
    message = str(error.value)
    assert f"{directory.name}/lesson.toml" in message
    assert f"'{field}'" in message


@pytest.mark.parametrize("field", ["title", "text"])
def test_each_step_field_corrupted(lesson_copy, field):
    directory, data = lesson_copy
    del data["steps"][0][field]
    _dump(data, directory / "lesson.toml")
    with pytest.raises(LessonError, match=rf"steps\[0\]: missing field '{field}'"):
        load_lesson(directory)


def test_unknown_check_kind_and_bad_check_field(lesson_copy):
    directory, data = lesson_copy
    data["steps"][0]["checks"] = [{"kind": "node_running"}]
    _dump(data, directory / "lesson.toml")
    with pytest.raises(LessonError, match=r"checks\[0\]: kind 'node_running' needs field 'node'"):
        load_lesson(directory)
    data["steps"][0]["checks"] = [{"kind": "telepathy"}]
    _dump(data, directory / "lesson.toml")
    with pytest.raises(LessonError, match="unknown kind 'telepathy'"):
        load_lesson(directory)


def test_paths_cannot_escape(lesson_copy):
    directory, data = lesson_copy
    data["steps"][0]["text"] = "../../../etc/passwd"
    _dump(data, directory / "lesson.toml")
    with pytest.raises(LessonError, match="leaves"):
        load_lesson(directory)


def test_invalid_toml_is_reported_and_the_rest_still_loads(tmp_path):
    for source in sorted(p for p in LESSONS_DIR.iterdir() if p.is_dir())[:2]:
        shutil.copytree(source, tmp_path / source.name)
    broken = sorted(tmp_path.iterdir())[0]
    (broken / "lesson.toml").write_text("title = [unclosed")
    course = load_course(tmp_path)
    assert len(course.lessons) == 1
    assert len(course.errors) == 1 and "not valid TOML" in course.errors[0]


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ({"kind": "open_panel", "panel": "Scene"}, "there is no tab 'Scene'"),
        ({"kind": "start", "catalog_node": "warp_drive"}, "no catalog node 'warp_drive'"),
        ({"kind": "start_group", "group": "everything"}, "no launch group 'everything'"),
        ({"kind": "lifecycle", "node": "lifecycle_talker", "transition": "configure"},
         "no catalog entry creates the ROS node 'lifecycle_talker'"),
        ({"kind": "stop", "node": "/talker"}, "kind 'stop' needs field 'catalog_node'"),
    ],
)  # fmt: skip
def test_names_that_do_not_exist_in_the_product_are_errors(lesson_copy, spec, message):
    directory, data = lesson_copy
    data["steps"][0]["actions"] = [spec]
    _dump(data, directory / "lesson.toml")
    with pytest.raises(LessonError, match=message):
        load_lesson(directory)


def test_a_check_naming_a_node_nobody_starts_is_an_error(lesson_copy):
    directory, data = lesson_copy
    data["steps"][0]["checks"] = [{"kind": "node_running", "node": "/warp_drive"}]
    _dump(data, directory / "lesson.toml")
    with pytest.raises(LessonError, match="no catalog entry creates the ROS node '/warp_drive'"):
        load_lesson(directory)


def test_a_broken_lesson_is_listed_in_the_outline_errors(tmp_path):
    source = LESSONS_DIR / "05_topics"
    shutil.copytree(source, tmp_path / source.name)
    toml = tmp_path / source.name / "lesson.toml"
    assert 'catalog_node = "' in toml.read_text()
    toml.write_text(toml.read_text().replace('catalog_node = "', 'catalog_node = "x_', 1))
    course = load_course(tmp_path)
    assert course.lessons == ()
    assert "no catalog node 'x_" in course.errors[0]


def test_schema_and_runtime_share_one_registry_of_kinds():
    from app.lessons import runtime
    from app.lessons.kinds import ACTION_KINDS, CHECK_KINDS

    assert set(runtime._ACTIONS) == set(ACTION_KINDS)
    assert set(runtime._CHECKS) == set(CHECK_KINDS)


def test_a_console_action_runs_only_a_ros2_command(lesson_copy):
    directory, data = lesson_copy
    data["steps"][0]["actions"] = [{"kind": "console", "command": "rm -rf / ; ros2 topic list"}]
    _dump(data, directory / "lesson.toml")
    with pytest.raises(LessonError, match="a console command is one line that starts with 'ros2 '"):
        load_lesson(directory)
