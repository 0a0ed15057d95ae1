"""The tf2 and URDF lessons: their TF check kinds are used and validated like every other
kind. Where they sit in the course is tests/unit/test_course_order.py's business.
"""

from __future__ import annotations

import pytest

from app.lessons.kinds import CHECK_KINDS
from app.lessons.schema import LessonError, parse_spec
from tests.course_data import shared_course

TF_KINDS = {"tf_frame", "tf_transform", "tf_moves", "tf_late_joiner"}


def test_the_units_use_every_tf_check_kind():
    course = shared_course()
    used = {
        check.kind
        for lesson_id in ("16_tf2_turtlesim", "17_tf2_time", "18_urdf_robot")
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
