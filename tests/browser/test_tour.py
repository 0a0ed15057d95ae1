"""Every tab renders for a learner, with nodes running: each shows what it is for."""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

from app.ui import TAB_NAMES
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
    "Turtlesim": "ros2 run turtlesim turtlesim_node",
    "Graph": "ros2 node list",
    "Echo": "data: 'Hello World:",
    "3D view": "draws live topics",
    "TF": "No TF frames yet",
    "Topics": "/chatter",
    "Parameters": "A node's parameters are settings",
    "Console": "Type a command as the tutorials write it",
    "Services": "Show parameter services",
    "Actions": "No action on the graph",
    "Lifecycle": "Start lifecycle_talker in the Nodes tab",
    "Logs": "records seen",
    "Bags": "Record topics into a bag",
}


def test_every_tab_renders_without_errors(page):
    open_tab(page, "Nodes")
    choose(page, "Launch group", "chatter_demo")
    click(page, "Start group")
    expect_text(page, "Started group")
    tabs = page.get_by_role("tab")
    expect(tabs.first).to_be_visible()
    names = [name.strip() for name in tabs.all_inner_texts()]
    # The stage window docked on the left has a tab of its own; the code window is off stage.
    side = [name for name in names if name in SIDE_WINDOW_TABS + STAGE_TABS]
    assert side == list(STAGE_TABS)
    names = [name for name in names if name not in STAGE_TABS]
    assert tuple(names) == TAB_NAMES == tuple(EXPECTED)
    for name in names:
        open_tab(page, name)
        expect_text(page, EXPECTED[name])
        page.screenshot(path=str(ARTIFACTS / f"tour-{name.replace(' ', '_')}.png"))
        text = page.locator("body").inner_text()
        assert "Traceback" not in text, name
        assert cut_off_at_panel_edge(page, "[role=tab]", "Lessons") == [], (
            f"{name}: cut off at the panel's right edge"
        )
