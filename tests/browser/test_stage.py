"""The stage follows the lesson: each unit puts on stage what its data names, the learner
can pick another, and the live graph grows and shows messages moving on /chatter."""

from __future__ import annotations

import time

import pytest
from playwright.sync_api import Page, expect

from app.lessons.schema import load_course
from app.stage import STAGES
from tests.browser.helpers import choose, open_tab, start_node
from tests.conftest import ARTIFACTS

pytestmark = [pytest.mark.browser, pytest.mark.ros]

SIZES = [(1366, 768), (1920, 1080)]


def _open(browser, dashboard, size: tuple[int, int]) -> Page:
    context = browser.new_context(viewport={"width": size[0], "height": size[1]})
    page = context.new_page()
    page.goto(dashboard.url)
    page.get_by_role("tab", name="Lessons").wait_for()
    return page


def _on_stage(page: Page) -> list[str]:
    """Which stages the page shows, read from what is visible ([] is the 3D scene)."""
    graph = page.locator("svg.stage-graph").filter(visible=True).count() > 0
    code = page.get_by_role("tab", name="Code of this lesson").filter(visible=True).count() > 0
    turtle = page.get_by_text("Turtlesim's window is in the").filter(visible=True).count() > 0
    return [name for name, on in (("graph", graph), ("code", code), ("turtlesim", turtle)) if on]


def _wait_stage(page: Page, wanted: str, timeout: float = 5.0) -> None:
    """Exactly ``wanted`` on stage within ``timeout`` (a window may take a frame to go)."""
    expected = [] if wanted == "scene" else [wanted]
    deadline = time.monotonic() + timeout
    while (seen := _on_stage(page)) != expected:
        assert time.monotonic() < deadline, f"on stage {seen}, the lesson names {wanted!r}"
        page.wait_for_timeout(100)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_every_lesson_puts_its_stage_on_and_the_learner_can_switch(browser, dashboard, size):
    page = _open(browser, dashboard, size)
    try:
        # The course as the dashboard loaded it (lessons are being written in this tree).
        for lesson in load_course().lessons:
            choose(page, "Lesson", f"{lesson.unit:02d} · {lesson.title}")
            _wait_stage(page, lesson.stage)
            # The step's controls stay in view: Next is on screen without scrolling the page.
            expect(page.get_by_role("button", name="Next", exact=True)).to_be_visible()
        for name, label in STAGES.items():  # the learner's own choice
            choose(page, "On stage", label)
            _wait_stage(page, name)
    finally:
        page.screenshot(path=str(ARTIFACTS / f"stage-lessons-{size[0]}.png"))
        page.context.close()


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_graph_grows_and_messages_move_on_chatter(browser, dashboard, size):
    page = _open(browser, dashboard, size)
    try:
        choose(page, "On stage", STAGES["graph"])
        talker = page.locator('svg.stage-graph g.sg-vertex[data-name="/talker"]')
        start_node(page, "talker")  # returns once the panel says "Started talker"
        started = time.monotonic()
        expect(talker).to_be_visible(timeout=5_000)
        grew = time.monotonic() - started
        assert grew < 1.5, f"/talker appeared {grew:.2f} s after Start"
        start_node(page, "listener")
        expect(page.locator('svg.stage-graph g.sg-vertex[data-name="/listener"]')).to_be_visible()
        dots = page.locator('svg.stage-graph circle.sg-dot[data-topic="/chatter"]')
        # talker -> /chatter -> listener, 2 Hz: two dots on each of the two edges.
        expect(dots).to_have_count(4, timeout=10_000)
        expect(page.get_by_text("2.0 Hz").filter(visible=True).first).to_be_visible()
        # The dots move in the browser: their places change between looks.
        places = set()
        for _ in range(6):
            box = dots.first.bounding_box()
            assert box is not None
            places.add((round(box["x"]), round(box["y"])))
            page.wait_for_timeout(150)
        assert len(places) >= 3, f"the first dot was at {places} in 0.9 s"
        # ...without the server resending the picture for them (a steady 2 Hz draws once).
        page.wait_for_timeout(3000)
        alive = page.evaluate("() => document.querySelector('svg.stage-graph').getCurrentTime()")
        assert alive > 2.5, f"the picture was replaced {alive:.1f} s ago"
        open_tab(page, "Nodes")  # the stage stays while the learner uses the tools
        expect(talker).to_be_visible()
    finally:
        page.screenshot(path=str(ARTIFACTS / f"stage-graph-{size[0]}.png"))
        page.context.close()
