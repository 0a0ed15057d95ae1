"""A link into the course opens where it points (an LMS's launch lands on its activity):
``?lesson=ID`` opens that lesson, ``?exercise=SLUG`` that exercise, and an id the course
does not have changes nothing."""

from __future__ import annotations

import re

from playwright.sync_api import expect

from tests.browser.helpers import expect_text, open_page
from tests.course_data import shared_course, shared_exercises

LESSON = next(lesson for lesson in shared_course().lessons if lesson.unit == 5)
EXERCISE = shared_exercises().get("wall_stop")


def test_the_address_opens_a_lesson_or_an_exercise(browser, dashboard):
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    page = context.new_page()
    try:
        open_page(page, f"{dashboard.url}?lesson={LESSON.id}")
        position = re.compile(rf"Lesson 5 of \d+ · Step 1 of {len(LESSON.steps)}")
        expect_text(page, position)
        expect(page.get_by_label("Lesson", exact=True)).to_have_value(
            f"{LESSON.unit:02d} · {LESSON.title}"
        )

        page.goto(f"{dashboard.url}?exercise={EXERCISE.slug}")
        expect_text(page, re.compile(rf"^{re.escape(EXERCISE.title)}$"))
        expect(page.get_by_label("Exercise", exact=True)).to_have_value(
            re.compile(rf"^{EXERCISE.unit:02d} · {re.escape(EXERCISE.title)}")
        )

        page.goto(f"{dashboard.url}?lesson=no_such_lesson")
        expect_text(page, position)  # still where the learner was: nothing changed
    finally:
        context.close()
