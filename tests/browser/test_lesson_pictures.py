"""A lesson step's diagram shows in the real page, under its text, with its alt text."""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

from app.lessons.schema import load_course
from tests.browser.helpers import click_next, expect_text, go_to_step, open_tab

pytestmark = [pytest.mark.browser, pytest.mark.ros]
COURSE = load_course()


def _picture_steps():
    """The first step with a picture at index 0, and the first one further in."""
    steps = [
        (lesson, index)
        for lesson in COURSE.lessons
        for index, step in enumerate(lesson.steps)
        if step.image
    ]
    first = next(item for item in steps if item[1] == 0)
    later = next(
        (lesson, index)
        for lesson, index in steps
        if 0 < index < len(lesson.steps) - 1 and not lesson.steps[index + 1].image
    )
    return [first, later]


@pytest.mark.parametrize(
    "lesson, index", _picture_steps(), ids=lambda x: getattr(x, "id", str(x))
)  # fmt: skip
def test_a_step_shows_its_picture_and_the_next_step_does_not(page, lesson, index):
    step = lesson.steps[index]
    open_tab(page, "Lessons")
    go_to_step(page, lesson, index)
    expect_text(page, f"Step {index + 1} of {len(lesson.steps)}: {step.title}")

    picture = page.get_by_role("img", name=step.image_alt, exact=True)
    expect(picture).to_be_visible(timeout=10_000)
    box = picture.bounding_box()
    assert box is not None and box["width"] > 250 and box["height"] > 100, box
    decoded = picture.evaluate("img => img.complete && img.naturalWidth")
    assert decoded and decoded > 0, "the browser could not decode the SVG"

    click_next(page)
    expect_text(page, f"Step {index + 2} of {len(lesson.steps)}")
    if not lesson.steps[index + 1].image:
        expect(page.get_by_role("img", name=step.image_alt, exact=True)).to_have_count(0)
