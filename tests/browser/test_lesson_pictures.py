"""A lesson step's diagram shows in the real page, under its text, with its alt text."""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

from tests.browser.helpers import click_next, expect_text, go_to_step, open_tab
from tests.course_data import shared_course

pytestmark = [pytest.mark.browser, pytest.mark.ros]
COURSE = shared_course()


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


def test_a_diagram_on_stage_fills_the_stage_and_is_not_repeated_in_the_text(page):
    """A step about an idea puts its diagram on stage: whole, in view, as large as the
    window lets it be, and not a second time in the column."""
    lesson, index = next(
        (lesson, index)
        for lesson in COURSE.lessons
        for index, step in enumerate(lesson.steps)
        if (step.stage or lesson.stage) == "picture"
    )
    step = lesson.steps[index]
    open_tab(page, "Lessons")
    go_to_step(page, lesson, index)
    expect_text(page, f"Step {index + 1} of {len(lesson.steps)}: {step.title}")
    picture = page.get_by_role("img", name=step.image_alt, exact=True)
    expect(picture).to_have_count(1)
    expect(picture).to_be_visible(timeout=10_000)
    view = page.viewport_size
    assert view is not None
    box = picture.bounding_box()
    assert box is not None
    assert box["x"] < 40, box  # on the stage, at the window's left
    assert 0 <= box["y"] and box["y"] + box["height"] <= view["height"], (box, view)
    assert box["height"] >= 0.6 * view["height"], (box, view)  # bigger than the column's
