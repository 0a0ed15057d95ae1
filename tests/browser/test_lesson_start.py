"""A lesson starts clean (issue 37): opening another lesson takes what the last one left
out of the 3D view, names the nodes still running from it with one button that stops
them all, and the step card says where the learner is and what Next would skip."""

from __future__ import annotations

import re
import time

import pytest
from playwright.sync_api import Page, expect

from tests.browser.helpers import (
    NEXT_OR_SKIP,
    choose,
    expect_text,
    open_lesson,
    open_page,
    open_tab,
    start_node,
)
from tests.conftest import ARTIFACTS
from tests.course_data import shared_course

pytestmark = [pytest.mark.browser, pytest.mark.ros]

SIZES = [(1366, 768), (1920, 1080)]
COURSE = shared_course()
LAMP = "/tf_view/frames/lamp"  # the frame in the 3D view (its axes and name hang under it)
# Drawn in the scene: the page holds its 3D object (a removed node's entry is null).
_HAS_NODE = "(n) => !!(window.__viserMutable && window.__viserMutable.nodeRefFromName[n])"


def _open_lesson(page: Page, lesson_id: str) -> None:
    lesson = COURSE.lesson(lesson_id)
    assert lesson is not None
    open_tab(page, "Lessons")
    open_lesson(page, lesson)
    expect_text(page, f"Step 1 of {len(lesson.steps)}: {lesson.steps[0].title}")


def _console(page: Page, command: str) -> None:
    open_tab(page, "Console")
    field = page.get_by_text("Command", exact=True).locator("visible=true").first
    field.locator("xpath=ancestor::div[contains(@class,'mantine-Flex-root')][1]//input").fill(
        command
    )
    page.get_by_role("button", name="Run", exact=True).click()
    expect_text(page, "[exit code 0]", timeout=60_000)


def _in_view(page: Page, name: str) -> bool:
    return bool(page.evaluate(_HAS_NODE, name))


def _wait_in_view(page: Page, name: str, wanted: bool, timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while _in_view(page, name) != wanted:
        assert time.monotonic() < deadline, f"{name} {'never came' if wanted else 'stayed'}"
        page.wait_for_timeout(200)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_a_new_lesson_starts_clean_and_names_what_is_left(browser, dashboard, size):
    context = browser.new_context(viewport={"width": size[0], "height": size[1]})
    page = context.new_page()
    try:
        open_page(page, dashboard.url)
        _open_lesson(page, "05_topics")
        total = len(COURSE.lessons)
        number = [lesson.id for lesson in COURSE.lessons].index("05_topics") + 1
        expect_text(page, f"Lesson {number} of {total} · Step 1 of 6")
        # Next says it would skip: the talker is not running yet.
        skip = page.get_by_role("button", name="Skip (3 checks not passed)", exact=True)
        expect(skip).to_be_visible()
        back = page.get_by_role("button", name="Back", exact=True)
        colours = [
            b.evaluate("(e) => getComputedStyle(e).backgroundColor")
            for b in (back, skip, page.get_by_role("button", name="Start talker", exact=True))
        ]
        assert colours[0] != colours[1], f"Back and Next look the same: {colours}"
        # The lesson's work: a talker, and a frame broadcast from the Console.
        page.get_by_role("button", name="Start talker", exact=True).click()
        expect(page.get_by_role("button", name="Next", exact=True)).to_be_visible(timeout=30_000)
        _console(
            page, "ros2 run tf2_ros static_transform_publisher --x 1 --frame-id world "
            "--child-frame-id lamp",
        )  # fmt: skip
        _wait_in_view(page, LAMP, True, 60.0)

        # The next lesson names both and stops them with one click; a still published
        # frame stays in view.
        _open_lesson(page, "06_qos")
        leftover = page.get_by_role(
            "button",
            name=re.compile(r"^Stop 2 nodes left from earlier lessons: "),
        )
        expect(leftover).to_be_visible(timeout=10_000)
        named = leftover.inner_text()
        assert "/talker" in named and "/static_transform_publisher" in named, named
        assert _in_view(page, LAMP), "lamp is still published: it stays"
        leftover.click()
        expect(leftover).to_be_hidden(timeout=30_000)
        talker = page.locator('svg.stage-graph g.sg-vertex[data-name="/talker"]')
        expect(talker).to_have_count(0, timeout=30_000)
        # The TF tool says when lamp's broadcaster has left the graph (DDS takes a moment).
        open_tab(page, "TF")
        expect_text(page, "publisher gone", timeout=60_000)

        # Another lesson: the frame nobody sends any more is gone from the 3D view.
        _open_lesson(page, "07_services")
        _wait_in_view(page, LAMP, False, 10.0)
        choose(page, "On stage", "3D scene")
        expect(page.get_by_text("lamp", exact=True).filter(visible=True)).to_have_count(0)
        # Nothing is left running: no leftover button, and this step's Stop (if any) is
        # greyed while there is nothing to stop.
        expect(page.get_by_role("button", name=re.compile("left from earlier"))).to_have_count(0)
    finally:
        page.screenshot(path=str(ARTIFACTS / f"lesson-start-{size[0]}.png"))
        context.close()


def test_a_stop_with_nothing_to_stop_is_greyed(browser, dashboard):
    page = browser.new_page(viewport={"width": 1366, "height": 768})
    try:
        open_page(page, dashboard.url)
        _open_lesson(page, "05_topics")
        lesson = COURSE.lesson("05_topics")
        assert lesson is not None
        last = lesson.steps[-1]
        for at in range(len(lesson.steps) - 1):
            expect_text(page, f"Step {at + 1} of {len(lesson.steps)}")
            page.get_by_role("button", name=NEXT_OR_SKIP).click()
        expect_text(page, f"Step {len(lesson.steps)} of {len(lesson.steps)}: {last.title}")
        stops = [a.get("label") for a in last.actions if a.kind.startswith("stop")]
        assert stops, "the last step of the topics lesson stops its nodes"
        for label in stops:
            expect(page.get_by_role("button", name=label, exact=True)).to_be_disabled()
        start_node(page, "talker")
        open_tab(page, "Lessons")
        talker_stop = next(
            a.get("label") for a in last.actions if a.get("catalog_node") == "talker"
        )
        expect(page.get_by_role("button", name=talker_stop, exact=True)).to_be_enabled(
            timeout=10_000
        )
    finally:
        page.screenshot(path=str(ARTIFACTS / "lesson-stop-greyed.png"))
        page.context.close()
