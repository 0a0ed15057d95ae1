"""50 start/stop cycles of a launch group at random moments: no leftovers, no stale nodes."""

from __future__ import annotations

import random
import time

import pytest

from tests.conftest import wait_until
from tests.faults.helpers import (
    all_quiet,
    choose,
    graph_nodes,
    live_children,
    overview,
    record,
    rss_mb,
)
from tests.wire_client import WireClient

pytestmark = pytest.mark.ros

CYCLES = 50


def test_fifty_random_start_stop_cycles(dashboard):
    rng = random.Random(8)
    client = WireClient(dashboard.url)
    pid = dashboard.proc.pid
    try:
        wait_until(lambda: client.find("Start group", "GuiButtonMessage"), what="Nodes panel")
        choose(client, "Launch group", "chatter_demo")  # talker + listener + listener2
        time.sleep(0.3)
        started = time.monotonic()
        rss_after_warmup = None
        spawned = 0
        for cycle in range(CYCLES):
            client.click("Start group")
            wait_until(lambda: len(live_children(pid)) >= 3, timeout=20, what="3 node processes")
            spawned += 3
            # Random moments: mid-import, mid-DDS-join, or well after joining.
            time.sleep(rng.choice([0.0, rng.uniform(0.05, 0.4), rng.uniform(0.4, 2.0)]))
            client.click("Stop group")
            wait_until(
                lambda: all_quiet(client, pid),
                timeout=20,
                what=f"every node process to end (cycle {cycle})",
            )
            if cycle == 4:
                rss_after_warmup = rss_mb(pid)
        cycles_sec = time.monotonic() - started
        settled = time.monotonic()
        wait_until(
            lambda: graph_nodes(client) == ["/classroom_dashboard"],
            timeout=30,
            what="the graph to hold only the dashboard",
        )
        settle_sec = time.monotonic() - settled
        rss_end = rss_mb(pid)
        table = overview(client)
    finally:
        client.close()
    assert "Traceback" not in dashboard.log()
    assert "✗" not in table, "a stopped node was reported as crashed"
    record(
        "50 start/stop cycles",
        cycles=CYCLES,
        processes_started=spawned,
        leftover_processes=0,
        stale_graph_nodes=0,
        seconds=round(cycles_sec, 1),
        graph_settled_sec=round(settle_sec, 1),
        rss_after_5_cycles_mb=round(rss_after_warmup or 0, 1),
        rss_end_mb=round(rss_end, 1),
        rss_growth_mb=round(rss_end - (rss_after_warmup or rss_end), 1),
    )
    assert rss_end - rss_after_warmup < 60, "the dashboard's memory keeps growing"
