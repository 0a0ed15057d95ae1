"""The learner's screen keeps one layout (issue 37): the stage is all the room left of the
control column in every lesson, whichever stage came before; the graph's text stays
readable; the 3D scene is drawn in the stage's area, not under the column."""

from __future__ import annotations

import time

import pytest
from playwright.sync_api import Page

from app.lessons.schema import load_course
from tests.browser.helpers import choose
from tests.conftest import ARTIFACTS

pytestmark = [pytest.mark.browser, pytest.mark.ros]

# A school laptop, a desk screen, and the laptop at 125 % browser zoom (its CSS pixels).
SIZES = [(1366, 768, 1.0), (1920, 1080, 1.0), (1093, 614, 1.25)]
# The graph, then the code (lesson 2), the graph again, the 3D scene, the graph again.
WALK = ("01_ros2_and_dds", "02_first_node", "03_topics", "12_images_opencv", "04_qos")
MIN_TEXT_PX = 11

# Where the stage and the column are, as drawn: the left dock (graph, code, turtlesim, TF)
# or the 3D canvas; the column is the window that holds the tool groups' tabs.
_LAYOUT = """() => {
  const shown = (e) => e && e.getBoundingClientRect().width > 0;
  const box = (e) => { const r = e.getBoundingClientRect();
    return {left: r.left, right: r.right, top: r.top, bottom: r.bottom}; };
  const learn = [...document.querySelectorAll('[role=tab]')]
    .find((t) => shown(t) && t.innerText.trim() === 'Learn');
  let column = learn;
  for (let e = learn; e && e.parentElement; e = e.parentElement)
    if (e.getBoundingClientRect().width < innerWidth * 0.6) column = e;
  const left = document.querySelector('[data-dock-region="left"]');
  const canvas = [...document.querySelectorAll('canvas')].find(shown);
  const texts = [...document.querySelectorAll('svg.stage-graph text')].filter(shown)
    .map((t) => parseFloat(getComputedStyle(t).fontSize) * t.getScreenCTM().a);
  const tab = (name) => [...document.querySelectorAll('[role=tab]')]
    .some((t) => shown(t) && t.innerText.trim() === name);
  const on = {graph: texts.length > 0, code: tab('Code of this lesson'), scene: !shown(left)};
  return {
    on,
    window: innerWidth, column: column && box(column),
    dock: shown(left) ? box(left) : null, canvas: canvas ? box(canvas) : null,
    smallest_text: texts.length ? Math.min(...texts) : null,
  };
}"""


def _stage_box(layout: dict, stage: str) -> dict | None:
    return layout["canvas"] if stage == "scene" else layout["dock"]


def _fills(layout: dict, stage: str) -> str:
    """'' when the stage spans from the window's left edge to the column; else what is off."""
    stage_box, column = _stage_box(layout, stage), layout["column"]
    if column is None or stage_box is None:
        return f"stage {stage_box}, column {column}"
    if stage_box["left"] > 2:
        return f"stage starts at x={stage_box['left']:.0f}"
    if stage_box["right"] > column["left"] + 1:
        return f"stage ends at {stage_box['right']:.0f}, under the column at {column['left']:.0f}"
    if stage_box["right"] < column["left"] - 24:
        return f"stage ends at {stage_box['right']:.0f}, the column starts at {column['left']:.0f}"
    return ""


def _settled(page: Page, stage: str, timeout: float = 10.0) -> dict:
    """The layout once the stage fills its room (the dock eases in), or the last one seen."""
    deadline = time.monotonic() + timeout
    while True:
        layout = page.evaluate(_LAYOUT)
        on = layout["on"].get(stage, True)
        if (on and not _fills(layout, stage)) or time.monotonic() > deadline:
            return layout
        page.wait_for_timeout(200)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}@{s[2]:g}")
def test_the_stage_is_all_the_room_left_of_the_column_in_every_lesson(browser, dashboard, size):
    width, height, zoom = size
    context = browser.new_context(
        viewport={"width": width, "height": height}, device_scale_factor=zoom
    )
    page = context.new_page()
    course = {lesson.id: lesson for lesson in load_course().lessons}
    try:
        page.goto(dashboard.url)
        page.get_by_role("tab", name="Lessons").wait_for()
        for lesson_id in WALK:
            lesson = course[lesson_id]
            choose(page, "Lesson", f"{lesson.unit:02d} · {lesson.title}")
            stage = lesson.steps[0].stage or lesson.stage
            layout = _settled(page, stage)
            off = _fills(layout, stage)
            assert not off, f"{lesson_id} ({stage}) at {width}x{height}: {off}; {layout}"
            if stage == "graph":
                # Drawn at its natural size: never shrunk below readable text.
                smallest = layout["smallest_text"]
                assert smallest is not None and smallest >= MIN_TEXT_PX - 0.01, (
                    f"{lesson_id}: graph text {smallest} px on screen"
                )
    finally:
        page.screenshot(path=str(ARTIFACTS / f"screen-layout-{width}.png"))
        context.close()
