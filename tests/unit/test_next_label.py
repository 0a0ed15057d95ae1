"""The step card's Next says where it leads: the next step, the next lesson by name, a skip
of checks not passed, or the course's end (where it leads nowhere)."""

from __future__ import annotations

from app.lessons.panel import COURSE_END, _next_label
from tests.course_data import shared_course

COURSE = shared_course()


def test_next_names_the_lesson_it_opens_on_a_lessons_last_step():
    following = COURSE.lessons[1]
    assert _next_label(0, following, last_step=False) == "Next"
    assert _next_label(0, following, last_step=True) == (
        f"Next lesson: {following.unit:02d} · {following.title}"
    )


def test_a_skip_says_how_many_checks_it_skips():
    following = COURSE.lessons[1]
    assert _next_label(1, following, last_step=False) == "Skip (1 check not passed)"
    assert _next_label(3, following, last_step=True) == "Skip (3 checks not passed)"


def test_the_course_ends_on_the_last_lessons_last_step():
    assert _next_label(0, None, last_step=True) == COURSE_END
    assert _next_label(2, None, last_step=True) == COURSE_END
    assert _next_label(0, None, last_step=False) == "Next"
