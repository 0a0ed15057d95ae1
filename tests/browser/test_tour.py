"""Every tab renders for a learner: no traceback, no error banner, with nodes running."""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

from tests.browser.helpers import choose, click, expect_text, open_tab
from tests.conftest import ARTIFACTS

pytestmark = [pytest.mark.browser, pytest.mark.ros]


def test_every_tab_renders_without_errors(page):
    open_tab(page, "Nodes")
    choose(page, "Launch group", "chatter_demo")
    click(page, "Start group")
    expect_text(page, "Started group")
    tabs = page.get_by_role("tab")
    expect(tabs.first).to_be_visible()
    names = [name.strip() for name in tabs.all_inner_texts()]
    assert {"Lessons", "Nodes", "Graph"} <= set(names)
    for name in names:
        open_tab(page, name)
        page.wait_for_timeout(700)
        page.screenshot(path=str(ARTIFACTS / f"tour-{name.replace(' ', '_')}.png"))
        text = page.locator("body").inner_text()
        assert "Traceback" not in text, name
