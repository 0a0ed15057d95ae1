"""Where the stage and the control column are drawn, and whether the stage fills all
the room left of the column (issue 37's one layout), read from the page."""

from __future__ import annotations

import time

from playwright.sync_api import Page

# Where the stage and the column are, as drawn: the left dock (graph, code, turtlesim, TF)
# or the 3D canvas; the column is the window that holds the tool groups' tabs.
STAGE_LAYOUT_JS = """() => {
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


def stage_fills(layout: dict, stage: str) -> str:
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


def settled_layout(page: Page, stage: str, timeout: float = 10.0) -> dict:
    """The layout once the stage fills its room (the dock eases in), or the last one seen."""
    deadline = time.monotonic() + timeout
    while True:
        layout = page.evaluate(STAGE_LAYOUT_JS)
        on = layout["on"].get(stage, True)
        if (on and not stage_fills(layout, stage)) or time.monotonic() > deadline:
            return layout
        page.wait_for_timeout(200)


MIN_TEXT_PX = 11  # the graph is drawn at its natural size: never shrunk below readable


def stage_problem(page: Page, stage: str) -> str:
    """'' when ``stage``, once settled, is all the room left of the column and (the graph)
    its text is readable on screen; else what is wrong (issue 37's one layout)."""
    layout = settled_layout(page, stage)
    if off := stage_fills(layout, stage):
        return f"{off}; {layout}"
    smallest = layout["smallest_text"]
    if stage == "graph" and (smallest is None or smallest < MIN_TEXT_PX - 0.01):
        return f"graph text {smallest} px on screen"
    return ""
