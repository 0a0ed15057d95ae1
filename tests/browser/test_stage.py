"""The stage follows the lesson: each unit puts on stage what its data names, the learner
can pick another, and the live graph grows and shows messages moving on /chatter."""

from __future__ import annotations

import time

import pytest
from playwright.sync_api import Page, expect

from app.lessons.schema import load_course
from app.stage import STAGES
from tests.browser.helpers import choose, open_tab, out_of_view, start_node, step_controls
from tests.conftest import ARTIFACTS

pytestmark = [pytest.mark.browser, pytest.mark.ros]

SIZES = [(1366, 768), (1920, 1080)]


def _open(browser, dashboard, size: tuple[int, int]) -> Page:
    context = browser.new_context(viewport={"width": size[0], "height": size[1]})
    page = context.new_page()
    page.goto(dashboard.url)
    page.get_by_role("tab", name="Lessons").wait_for()
    return page


def _node_names(node) -> list[str]:
    return [ns.rstrip("/") + "/" + name for name, ns in node.get_node_names_and_namespaces()]


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


def _wait_side_by_side(page: Page, size: tuple[int, int], timeout: float = 10.0) -> None:
    """The stage sized to the window: it ends left of the control panel, which is on screen."""
    stage = page.get_by_role("tab", name="Stage")
    picker = page.get_by_label("On stage")
    deadline = time.monotonic() + timeout
    while True:
        a, b = stage.bounding_box(), picker.bounding_box()
        if a and b and b["x"] + b["width"] <= size[0] and a["x"] < b["x"]:
            panel_left = b["x"] - 100  # the picker's label sits left of the field
            stage_right = page.evaluate(
                "() => document.querySelector('svg.stage-graph').closest('[class*=Paper],div')"
                ".getBoundingClientRect().right"
            )
            if stage_right <= panel_left and stage_right > size[0] * 0.5:
                return
        assert time.monotonic() < deadline, f"stage {a}, control panel picker {b}"
        page.wait_for_timeout(200)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_every_lesson_puts_its_stage_on_and_the_learner_can_switch(browser, dashboard, size):
    page = _open(browser, dashboard, size)
    try:
        _wait_side_by_side(page, size)
        # The course as the dashboard loaded it (lessons are being written in this tree).
        for lesson in load_course().lessons:
            choose(page, "Lesson", f"{lesson.unit:02d} · {lesson.title}")
            _wait_stage(page, lesson.stage)
            # Every control of the step is in view without scrolling: title, buttons,
            # answers, checks, Back and Next.
            hidden = out_of_view(page, step_controls(page, lesson, 0))
            assert not hidden, f"{lesson.id} at {size}: " + "; ".join(hidden)
        for name, label in STAGES.items():  # the learner's own choice
            choose(page, "On stage", label)
            _wait_stage(page, name)
    finally:
        page.screenshot(path=str(ARTIFACTS / f"stage-lessons-{size[0]}.png"))
        page.context.close()


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_graph_grows_and_messages_move_on_chatter(browser, dashboard, probe, size):
    page = _open(browser, dashboard, size)
    try:
        choose(page, "On stage", STAGES["graph"])
        talker = page.locator('svg.stage-graph g.sg-vertex[data-name="/talker"]')
        start_node(page, "talker")
        # From the moment DDS lists /talker (a probe node sees it) to the box on stage.
        on_ros_graph = on_stage = None
        deadline = time.monotonic() + 20
        while (on_stage is None or on_ros_graph is None) and time.monotonic() < deadline:
            now = time.monotonic()
            if on_ros_graph is None and "/talker" in _node_names(probe.node):
                on_ros_graph = now
            if on_stage is None and talker.count():
                on_stage = now
            page.wait_for_timeout(30)
        assert on_ros_graph is not None and on_stage is not None, "/talker never showed"
        grew = on_stage - on_ros_graph  # negative: the stage saw it before the probe did
        assert grew < 1.0, f"/talker on stage {grew:.2f} s after it joined the ROS graph"
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
        # A click on a box inspects it, as `ros2 topic info` / `ros2 node info` would.
        page.locator('svg.stage-graph g.sg-vertex[data-name="/chatter"] a').click()
        expect(page.get_by_text("publishers: /talker").filter(visible=True)).to_be_visible()
        expect(page.get_by_text("subscribers: /listener").filter(visible=True)).to_be_visible()
        page.locator('svg.stage-graph g.sg-vertex[data-name="/listener"] a').click()
        expect(page.get_by_text("Node /listener").filter(visible=True)).to_be_visible()
        open_tab(page, "Nodes")  # the stage stays while the learner uses the tools
        expect(talker).to_be_visible()
    finally:
        page.screenshot(path=str(ARTIFACTS / f"stage-graph-{size[0]}.png"))
        page.context.close()
