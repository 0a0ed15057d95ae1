"""Every tool renders for a learner, with nodes running: each shows what it is for, and the
tools sit in a row of groups (Learn, Run, Inspect, See, Record), each group's tools in one row."""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

from app.ui import TAB_NAMES, TOOL_GROUPS
from tests.browser.helpers import choose, click, cut_off_at_panel_edge, expect_text, open_tab
from tests.conftest import ARTIFACTS

pytestmark = [pytest.mark.browser, pytest.mark.ros]

SIDE_WINDOW_TABS = ("Code of this lesson", "Your code")
STAGE_TABS = ("Stage",)  # the stage window; lesson 1 puts the graph on, the code off

# What each tab must show once talker, listener and listener2 run.
EXPECTED = {
    "Lessons": "Course outline",
    "Exercise": "Run my node",
    "Nodes": "All catalog nodes",
    "Console": "Type a command as the tutorials write it",
    "Turtlesim": "ros2 run turtlesim turtlesim_node",
    "Graph": "ros2 node list",
    "TF": "No TF frames yet",
    "Topics": "/chatter",
    "Echo": "data: 'Hello World:",
    "Logs": "records seen",
    "Services": "Show parameter services",
    "Actions": "No action on the graph",
    "Parameters": "A node's parameters are settings",
    "Lifecycle": "Start lifecycle_talker in the Nodes tab",
    "3D view": "draws live topics",
    "Bags": "Record topics into a bag",
}


# The top edge of each visible tab named in the list, read in one frame: read one by one,
# a column still scrolling moved the later ones (rehearsal ci66: 652 and 669 px, a
# 17 px scroll, not a second row of tabs, which starts a tab's height lower).
_TOPS_JS = """(names) => names.map((name) => {
  const tab = [...document.querySelectorAll('[role=tab]')].find((t) =>
    t.getBoundingClientRect().width > 0 && t.innerText.trim() === name);
  return tab ? Math.round(tab.getBoundingClientRect().top) : null;
})"""


def _row_of(page, names) -> list[float]:
    """The top edges of the visible tabs named ``names`` (one value: they share a row)."""
    tops = page.evaluate(_TOPS_JS, list(names))
    missing = [name for name, top in zip(names, tops, strict=True) if top is None]
    assert not missing, f"tabs {missing} are not on screen"
    return sorted(set(tops))


def test_every_tab_renders_without_errors(page):
    open_tab(page, "Nodes")
    choose(page, "Launch group", "chatter_demo")
    click(page, "Start group")
    expect_text(page, "Started group")
    tabs = page.get_by_role("tab").filter(visible=True)
    expect(tabs.first).to_be_visible()
    names = [name.strip() for name in tabs.all_inner_texts()]
    # The stage window docked on the left has a tab of its own; the code window is off stage.
    side = [name for name in names if name in SIDE_WINDOW_TABS + STAGE_TABS]
    assert side == list(STAGE_TABS)
    assert [name for name in names if name in TOOL_GROUPS] == list(TOOL_GROUPS)
    assert len(_row_of(page, TOOL_GROUPS)) == 1, "the groups' tabs wrap onto a second row"
    assert TAB_NAMES == tuple(EXPECTED)
    for name in TAB_NAMES:
        open_tab(page, name)
        expect_text(page, EXPECTED[name])
        group = next(g for g, tools in TOOL_GROUPS.items() if name in tools)
        assert len(_row_of(page, TOOL_GROUPS[group])) == 1, f"{group}'s tools wrap"
        page.screenshot(path=str(ARTIFACTS / f"tour-{name.replace(' ', '_')}.png"))
        text = page.locator("body").inner_text()
        assert "Traceback" not in text, name
        assert cut_off_at_panel_edge(page, "[role=tab]", "Learn") == [], (
            f"{name}: cut off at the panel's right edge"
        )
