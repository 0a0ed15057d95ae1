"""The course as a learner meets it: lessons numbered 1..N in the order they are taken (the
folder's prefix is the number the picker, the position line and the teacher's view show),
the capstone last of the core course (navigation units follow it), and no lesson so long
that its step list stops being a plan.
"""

from __future__ import annotations

import shutil

from app.lessons.schema import LESSONS_DIR, load_course
from tests.course_data import shared_course

COURSE_ORDER = [
    "01_ros2_and_dds", "02_turtlesim_cli", "03_turtlesim_record_launch", "04_first_node",
    "05_topics", "06_qos", "07_services", "08_interfaces", "09_actions", "10_parameters",
    "11_lifecycle", "12_launch", "13_executors", "14_images_opencv", "15_frames_and_arm",
    "16_tf2_turtlesim", "17_tf2_time", "18_urdf_robot", "19_wheeled_robot",
    "20_workspaces_packages", "21_bags", "22_slam_capstone", "23_maps",
    "24_navigation",
]  # fmt: skip
# After the capstone that closes the core course, units that go on towards navigation.
BEYOND_THE_CAPSTONE = {"23_maps", "24_navigation"}
MOST_STEPS = 12
# Longer on purpose: its second half changes the package its first half built.
LONG_ON_PURPOSE = {"20_workspaces_packages"}


def test_lessons_are_numbered_one_to_n_in_course_order_with_the_capstone_last():
    course = shared_course()
    assert not course.errors
    assert [lesson.id for lesson in course.lessons] == COURSE_ORDER
    assert [lesson.unit for lesson in course.lessons] == list(range(1, len(COURSE_ORDER) + 1))
    core = [lesson for lesson in course.lessons if lesson.id not in BEYOND_THE_CAPSTONE]
    assert "capstone" in core[-1].id
    assert [lesson.id for lesson in course.lessons[len(core) :]] == sorted(BEYOND_THE_CAPSTONE)


def test_no_lesson_is_too_long_to_follow():
    long = {
        lesson.id: len(lesson.steps)
        for lesson in shared_course().lessons
        if len(lesson.steps) > MOST_STEPS
    }
    assert set(long) == LONG_ON_PURPOSE, long


def test_a_gap_or_a_twice_used_number_is_an_error(tmp_path):
    for name, source in (("01_topics", "05_topics"), ("03_bags", "21_bags")):
        shutil.copytree(
            LESSONS_DIR / source, tmp_path / name, ignore=shutil.ignore_patterns("exercises")
        )
    errors = load_course(tmp_path).errors
    assert errors == ("lesson folders must be numbered 01..02 in course order",)
    (tmp_path / "03_bags").rename(tmp_path / "01_bags")
    assert load_course(tmp_path).errors == errors
    (tmp_path / "01_bags").rename(tmp_path / "02_bags")
    assert load_course(tmp_path).errors == ()


def test_a_lesson_may_not_carry_its_own_unit_number(tmp_path):
    folder = tmp_path / "01_topics"
    shutil.copytree(LESSONS_DIR / "05_topics", folder, ignore=shutil.ignore_patterns("exercises"))
    toml = folder / "lesson.toml"
    toml.write_text("unit = 3\n" + toml.read_text(encoding="utf-8"), encoding="utf-8")
    course = load_course(tmp_path)
    assert course.lessons == () and "'unit' is gone" in course.errors[0]
