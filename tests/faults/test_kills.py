"""SIGKILL of a node and of a browser: the dashboard tells the truth and keeps serving."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import urllib.request
import uuid
from pathlib import Path

import psutil
import pytest

from app import PROJECT_ROOT
from app.panels.nodes_panel import STALE_NOTE
from app.supervisor import NodeState
from tests.browser.helpers import expect_text, open_page, open_tab
from tests.conftest import BROWSER_EXECUTABLE, wait_until
from tests.faults.helpers import live_children, overview, record
from tests.wire_client import WireClient

pytestmark = pytest.mark.ros


def _row(client: WireClient, name: str) -> str:
    return next((r for r in overview(client).splitlines() if r.startswith(f"| {name} |")), "")


def test_sigkilled_node_is_reported_crashed_and_stale_then_restarts(dashboard):
    client = WireClient(dashboard.url)
    try:
        wait_until(lambda: client.find("Start", "GuiButtonMessage"), what="Nodes panel")
        client.click("Start")  # talker
        wait_until(lambda: "running" in _row(client, "talker"), timeout=30, what="talker running")
        (talker,) = live_children(dashboard.proc.pid)
        killed_at = time.monotonic()
        os.kill(talker.pid, signal.SIGKILL)
        row = wait_until(
            lambda: "killed by SIGKILL" in (r := _row(client, "talker")) and r,
            what="the crash in the Nodes panel",
        )
        shown_after = time.monotonic() - killed_at
        assert "✗ crashed (killed by SIGKILL)" in row
        assert STALE_NOTE in row, row  # DDS still lists /talker until its lease expires
        client.click("Start")
        wait_until(lambda: "running" in _row(client, "talker"), timeout=30, what="a new talker")
        assert STALE_NOTE not in _row(client, "talker")
        (again,) = live_children(dashboard.proc.pid)
        assert again.pid != talker.pid
    finally:
        client.close()
    record(
        "SIGKILL of a node",
        shown_as=row.split("|")[2].strip(),
        seconds_to_show=round(shown_after, 2),
        restarted_with_new_pid=True,
    )


def test_a_talker_started_in_a_terminal_is_named_on_the_graph_not_just_stopped(dashboard):
    """The lessons teach `ros2 run`: a talker the learner started outside the dashboard is
    on the stage's graph, so the Nodes tool says so beside 'stopped', until it ends."""
    client = WireClient(dashboard.url)
    outside = subprocess.Popen([sys.executable, "-m", "nodes.talker"], cwd=PROJECT_ROOT)
    try:
        row = wait_until(
            lambda: "started elsewhere" in (r := _row(client, "talker")) and r,
            timeout=30,
            what="the outside talker named in the Nodes tool",
        )
        assert "○ stopped · /talker is on the graph" in row, row
        assert "started elsewhere" not in _row(client, "listener")
        outside.terminate()
        outside.wait(timeout=10)
        wait_until(
            lambda: "started elsewhere" not in _row(client, "talker"),
            timeout=30,
            what="the note gone with the talker",
        )
    finally:
        if outside.poll() is None:
            outside.kill()
            outside.wait()
        client.close()


def test_supervisor_knows_which_pids_ended(supervisor, probe):
    supervisor.start("talker")
    wait_until(
        lambda: "/talker" in [f"/{n}" for n, _ns in probe.node.get_node_names_and_namespaces()],
        what="/talker in the graph",
    )
    pid = supervisor.status("talker").pid
    os.kill(pid, signal.SIGKILL)
    status = wait_until(
        lambda: (s := supervisor.status("talker")).state is NodeState.CRASHED and s,
        what="the crash",
    )
    assert status.describe() == "crashed (killed by SIGKILL)"
    assert [(s.name, s.pid, s.exit_code) for s in supervisor.ended()] == [
        ("talker", pid, -signal.SIGKILL)
    ]
    graph = [f"/{n}" for n, _ns in probe.node.get_node_names_and_namespaces()]
    assert "/talker" in graph  # the lease has not run out yet...
    assert list(supervisor.stale_in_graph(graph)) == ["talker"]  # ...and we know it is stale


def test_a_killed_browser_leaves_the_server_serving(browser, dashboard):
    marker = f"--classroom-test-{uuid.uuid4().hex}"
    doomed = browser.browser_type.launch(
        executable_path=BROWSER_EXECUTABLE,
        args=["--no-sandbox", "--disable-dev-shm-usage", marker],
    )
    page = doomed.new_page()
    open_page(page, dashboard.url)
    open_tab(page, "Nodes")
    expect_text(page, "Catalog node")
    tagged = [p for p in psutil.process_iter(["cmdline"]) if marker in (p.info["cmdline"] or [])]
    # Kill the browser and its helpers (renderers, GPU process) at once.
    main = {p.pid: p for p in tagged}
    for proc in tagged:
        main.update({c.pid: c for c in proc.children(recursive=True)})
    main = list(main.values())
    assert main, "could not find the browser process"
    for proc in main:
        proc.send_signal(signal.SIGKILL)
    wait_until(lambda: not any(p.is_running() for p in main), what="the browser to die")
    assert dashboard.proc.poll() is None
    with urllib.request.urlopen(dashboard.url, timeout=10) as response:
        assert response.status == 200
    context = browser.new_context()
    try:
        fresh = context.new_page()
        open_page(fresh, dashboard.url)
        open_tab(fresh, "Nodes")
        expect_text(fresh, "Catalog node")
    finally:
        context.close()
    assert "Traceback" not in Path(dashboard.log_path).read_text()
    record("SIGKILL of a browser", server_kept_serving=True, new_page_works=True)
