"""The dashboard process itself: ordered shutdown, and no orphans when it is killed."""

from __future__ import annotations

import json
import signal
import subprocess
import time

import psutil
import pytest

from app.lessons.progress import ProgressStore
from tests.browser.helpers import choose, click, expect_text, open_tab
from tests.conftest import started_by, wait_until

pytestmark = [pytest.mark.browser, pytest.mark.ros]


def node_processes(dashboard_pid: int) -> list[psutil.Process]:
    return started_by(dashboard_pid)


def start_chatter_group(page) -> None:
    open_tab(page, "Nodes")
    choose(page, "Launch group", "chatter_demo")
    click(page, "Start group")
    expect_text(page, "Started group")


def _gone(pids: list[int]) -> bool:
    def alive(pid: int) -> bool:
        try:
            return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
        except psutil.NoSuchProcess:
            return False

    return not any(alive(pid) for pid in pids)


def test_sigkill_of_the_dashboard_leaves_no_node_running(page, dashboard, progress_dir):
    # The first lesson's first check passes at once: the progress file is being written.
    saved = progress_dir / "default.json"
    wait_until(saved.exists, what="the progress file")
    before = json.loads(saved.read_text())
    start_chatter_group(page)
    children = wait_until(
        lambda: len(kids := node_processes(dashboard.proc.pid)) >= 3 and kids,
        what="three node processes",
    )
    pids = [child.pid for child in children]
    dashboard.proc.send_signal(signal.SIGKILL)
    dashboard.proc.wait()
    wait_until(lambda: _gone(pids), timeout=10, what="every node process to end")
    after = ProgressStore("default", progress_dir)  # intact: no warning, nothing lost
    assert after.warning == ""
    for lesson, entry in before["lessons"].items():
        assert set(entry["passed"]) <= set(after.lesson(lesson)["passed"])


def test_sigterm_shuts_down_in_order_within_five_seconds(page, dashboard):
    start_chatter_group(page)
    children = wait_until(
        lambda: len(kids := node_processes(dashboard.proc.pid)) >= 3 and kids,
        what="three node processes",
    )
    pids = [child.pid for child in children]
    started = time.monotonic()
    dashboard.proc.send_signal(signal.SIGTERM)
    try:
        code = dashboard.proc.wait(timeout=10)
    except subprocess.TimeoutExpired:  # its log names the slow steps, and the stacks of a
        pytest.fail(f"still running 10 s after SIGTERM:\n{dashboard.log()[-6000:]}")  # stall
    elapsed = time.monotonic() - started
    assert code == 0, dashboard.log()
    assert elapsed < 5.0, f"shutdown took {elapsed:.1f} s:\n{dashboard.log()[-6000:]}"
    assert _gone(pids)
    assert "Stopped in" in dashboard.log()
