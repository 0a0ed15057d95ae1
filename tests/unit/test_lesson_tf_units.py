"""The tf2 and URDF units: placed after the frames unit without moving any saved progress.

Progress is stored per lesson id, the lesson's folder name
(app/lessons/progress.py), and the course is ordered by folder name. The two
units are ``13_tf2_turtlesim`` and ``13_urdf_robot``: they sort between
``13_frames_and_arm`` and ``14_slam_capstone``, and every older id stays as
it was. Their TF check kinds are validated like every other kind.
"""

from __future__ import annotations

import pytest

from app.lessons.kinds import CHECK_KINDS
from app.lessons.schema import LessonError, load_course, parse_spec

EARLIER_IDS = [
    "01_ros2_and_dds", "01_turtlesim_cli", "02_first_node", "03_topics", "04_qos",
    "05_services", "06_interfaces", "07_actions", "08_parameters", "09_lifecycle",
    "10_launch", "11_executors", "12_images_opencv", "13_frames_and_arm",
    "14_slam_capstone", "15_workspaces_packages", "16_bags",
]  # fmt: skip
TF_KINDS = {"tf_frame", "tf_transform", "tf_moves", "tf_late_joiner"}


def test_the_units_come_right_after_frames_and_no_older_id_changed():
    ids = [lesson.id for lesson in load_course().lessons]
    assert set(EARLIER_IDS) <= set(ids)
    at = ids.index("13_frames_and_arm")
    assert ids[at : at + 3] == ["13_frames_and_arm", "13_tf2_turtlesim", "13_urdf_robot"]
    assert ids.index("14_slam_capstone") > at + 2


def test_the_units_use_every_tf_check_kind():
    course = load_course()
    used = {
        check.kind
        for lesson_id in ("13_tf2_turtlesim", "13_urdf_robot")
        for step in course.lesson(lesson_id).steps  # type: ignore[union-attr]
        for check in step.checks
    }
    assert TF_KINDS <= used and TF_KINDS <= set(CHECK_KINDS)


@pytest.mark.parametrize(
    ("raw", "error"),
    [
        ({"kind": "tf_frame", "frame": "a"}, "needs field 'parent'"),
        ({"kind": "tf_transform", "target": "a", "source": "b"}, "needs field 'tolerance'"),
        (
            {"kind": "tf_transform", "target": "a", "source": "b", "tolerance": 1, "w": 1},
            "unknown field 'w'",
        ),
        ({"kind": "tf_moves", "frame": "a"}, "needs field 'at_least'"),
        ({"kind": "tf_late_joiner", "frame": "a", "parent": "b", "soon": 1}, "unknown field"),
    ],
)
def test_a_tf_check_with_a_wrong_field_is_a_clear_error(raw, error):
    with pytest.raises(LessonError, match=error):
        parse_spec(raw, CHECK_KINDS, "lesson.toml: steps[0].checks[0]")
