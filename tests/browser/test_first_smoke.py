"""A learner's first minutes: start talker and listener, watch, stop."""

from __future__ import annotations

import re
import time

import pytest
from playwright.sync_api import expect

from tests.browser.helpers import choose, click, expect_text, open_tab, start_node
from tests.conftest import wait_until
from tests.wire_client import WireClient

pytestmark = [pytest.mark.browser, pytest.mark.ros]


def test_start_watch_and_stop_talker_and_listener(page):
    start_node(page, "talker")
    start_node(page, "listener")

    open_tab(page, "Echo")
    expect(page.get_by_text(re.compile(r"data: 'Hello World: \d+'")).first).to_be_visible(
        timeout=30_000
    )
    # The page told the dashboard it shows Echo: each message shows as it comes (a tool no
    # page shows is refreshed every few seconds; app.ui.shown_tools). Watched once the
    # nodes' start has settled: until then every tool is refreshed at each pass.
    page.wait_for_timeout(4_000)
    counts = set()
    until = time.monotonic() + 6.0
    while time.monotonic() < until:
        texts = page.get_by_text(re.compile(r"data: 'Hello World: \d+'")).all_inner_texts()
        numbers = [int(n) for t in texts for n in re.findall(r"Hello World: (\d+)", t)]
        counts.add(max(numbers, default=-1))
        page.wait_for_timeout(100)
    assert len(counts) >= 4, f"Echo showed {sorted(counts)} in 6 s of a talker at 1 Hz"

    open_tab(page, "Graph")
    expect_text(page, "/listener")
    expect_text(page, "/talker")

    for name in ("talker", "listener"):
        open_tab(page, "Nodes")
        choose(page, "Catalog node", name)
        click(page, "Stop")
        expect_text(page, "stopped (exit code 0)")

    open_tab(page, "Graph")
    expect_text(page, "ros2 node list")

    def listed_as_running(name: str):
        # An item of the node list. A name DDS keeps after its process ended
        # (a "ghost", rare but real) is shown apart, as a stale name: allowed.
        return (
            page.locator("li").filter(has=page.get_by_text(name, exact=True)).filter(visible=True)
        )

    expect(listed_as_running("/talker")).to_have_count(0, timeout=15_000)
    expect(listed_as_running("/listener")).to_have_count(0, timeout=15_000)
    expect(listed_as_running("/classroom_dashboard")).to_have_count(1)  # the list is still drawn


def test_crashed_node_shows_exit_code_and_restarts(page):
    start_node(page, "crashing_node")
    expect_text(page, "crashed (exit code 1)", timeout=30_000)
    expect_text(page, "simulated bug")
    click(page, "Restart")
    expect_text(page, re.compile(r"Restart(ing|ed) crashing_node"))
    expect(page.get_by_text(re.compile(r"(starting|running) \(pid \d+\)")).first).to_be_visible(
        timeout=15_000
    )


def test_a_tool_is_built_when_the_learner_first_opens_it(page, dashboard):
    """The first page carries the tools it opens on; the others come with their first
    click (app/dashboard.py EAGER_TOOLS), in their place. What the dashboard sends is
    watched by a wire client that asks for no tool itself."""
    watcher = WireClient(dashboard.url, open_every_tool=False)
    try:
        wait_until(lambda: "Opening Nodes…" in watcher.markdown(), what="the placeholders")
        assert watcher.find("Catalog node") is None, "Nodes was built before any page opened it"
        open_tab(page, "Nodes")
        expect(page.get_by_label("Catalog node").filter(visible=True).first).to_be_visible(
            timeout=10_000
        )
        expect(page.get_by_text("Opening Nodes…")).to_have_count(0)
        assert watcher.find("Catalog node") is not None
        assert "Opening Nodes…" not in watcher.markdown()
        assert "Opening Bags…" in watcher.markdown()  # never opened: still not built
    finally:
        watcher.close()
