"""The check kinds the turtlesim unit added: registered, validated like every other kind.

Their behaviour on live nodes is walked in tests/integration/test_lessons_walk.py
(lessons 02 and 03 pass them; FAILING_CHECKS makes each one fail).
"""

from __future__ import annotations

import pytest

from app.lessons.kinds import CHECK_KINDS
from app.lessons.schema import LessonError, parse_spec
from tests.course_data import shared_course

POSE = "turtlesim/msg/Pose"


def test_the_turtlesim_lessons_use_the_new_kinds():
    course = shared_course()
    kinds = {
        check.kind
        for lesson_id in ("02_turtlesim_cli", "03_turtlesim_record_launch")
        for step in course.lesson(lesson_id).steps  # type: ignore[union-attr]
        for check in step.checks
    }
    assert {"moved_from", "moves_like", "rosout_contains"} <= kinds


@pytest.mark.parametrize(
    "raw",
    [
        {
            "kind": "moved_from",
            "topic": "/turtle1/pose",
            "type": POSE,
            "x": 1,
            "y": 2,
            "at_least": 1,
        },
        {"kind": "moves_like", "topic": "/a/pose", "type": POSE, "like": "/b/pose"},
        {"kind": "rosout_contains", "node": "/turtlesim", "text": "Oh no!"},
        {"kind": "rosout_contains", "node": "/turtlesim", "text": "Oh no!", "at_least": 2},
    ],
)
def test_well_formed_checks_load(raw):
    spec = parse_spec(raw, CHECK_KINDS, "here")
    assert spec.kind == raw["kind"]


@pytest.mark.parametrize(
    ("raw", "message"),
    [
        ({"kind": "moved_from", "topic": "/t", "type": POSE, "x": 1, "y": 2}, "'at_least'"),
        ({"kind": "moves_like", "topic": "/t", "type": POSE}, "needs field 'like'"),
        ({"kind": "rosout_contains", "node": "/nobody", "text": "x"}, "creates the ROS node"),
        ({"kind": "rosout_contains", "node": "/turtlesim", "text": "x", "level": 2}, "'level'"),
    ],
)
def test_malformed_checks_name_the_field(raw, message):
    with pytest.raises(LessonError, match=message):
        parse_spec(raw, CHECK_KINDS, "here")
