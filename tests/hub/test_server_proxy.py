"""The dashboard opened from a real Jupyter server's launcher, through jupyter-server-proxy.

What a learner on a JupyterHub does after logging in: open "ROS 2 Classroom"
from the launcher. The page, its websocket, the exercise editor and the
page links (a lifecycle edge) must all work under the proxy's base path, and
the dashboard's own loopback port must refuse anyone who did not come through
the proxy.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import psutil
import pytest
from playwright.sync_api import expect

from app import PROJECT_ROOT
from tests.browser.helpers import choose, expect_editor_loaded, expect_text, open_tab, start_node
from tests.conftest import ARTIFACTS, free_port, wait_until
from tests.course_data import shared_exercises

pytestmark = [pytest.mark.browser, pytest.mark.ros]

JUPYTER_TOKEN = "hub-test-token-0123456789"
EXERCISE = shared_exercises().get("multiply_service")


class JupyterServer:
    """``jupyter server`` as a real child process, in a session of its own."""

    def __init__(self, env: dict[str, str], home: Path) -> None:
        self.port = free_port()
        self.base = f"http://127.0.0.1:{self.port}"
        home.mkdir(parents=True, exist_ok=True)
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        self.log_path = ARTIFACTS / f"jupyter-{self.port}.log"
        self._log = open(self.log_path, "wb")
        self.proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "jupyter_server",
                "--ServerApp.ip=127.0.0.1",
                f"--ServerApp.port={self.port}",
                "--ServerApp.port_retries=0",
                f"--IdentityProvider.token={JUPYTER_TOKEN}",
                "--ServerApp.open_browser=False",
                f"--ServerApp.root_dir={home}",
                *(["--allow-root"] if os.geteuid() == 0 else []),  # CI machines run as root
            ],
            cwd=home,
            # A learner's single-user server: their own HOME, the project on the path.
            env={**env, "HOME": str(home), "PYTHONPATH": str(PROJECT_ROOT)},
            stdout=self._log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
        wait_until(self._ready, timeout=60, interval=0.3, what="the Jupyter server to answer")

    def _ready(self) -> bool:
        if self.proc.poll() is not None:
            pytest.fail(f"jupyter server exited early:\n{self.log_path.read_text()}")
        try:
            return self.get("/api/status")[0] == 200
        except OSError:
            return False

    def get(self, path: str, token: bool = True) -> tuple[int, bytes]:
        query = ("&" if "?" in path else "?") + f"token={JUPYTER_TOKEN}" if token else ""
        try:
            with urllib.request.urlopen(self.base + path + query, timeout=10) as answer:
                return answer.status, answer.read()
        except urllib.error.HTTPError as error:
            return error.code, error.read()

    def dashboards(self) -> list[psutil.Process]:
        """The dashboards this server's proxy started (its descendants)."""
        try:
            children = psutil.Process(self.proc.pid).children(recursive=True)
        except psutil.NoSuchProcess:
            return []
        # A dashboard's child between fork and exec still shows the dashboard's command
        # line (seen: two "dashboards" while it started a node): count the top one only.
        return [p for p in children if _is_dashboard(p) and not _is_dashboard(_parent(p))]

    def stop(self) -> None:
        """End the server and everything it started; the dashboard stops its nodes.

        Safe to call twice (the test calls it, then the fixture)."""
        spawned = self.dashboards()
        try:
            os.killpg(self.proc.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        try:
            self.proc.wait(20)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        _gone, alive = psutil.wait_procs(spawned, timeout=20)
        for proc in alive:
            proc.kill()
        self._log.close()
        assert not alive, f"the dashboard outlived its Jupyter server: {alive}"


def _parent(proc: psutil.Process) -> psutil.Process | None:
    try:
        return proc.parent()
    except psutil.Error:
        return None


def _is_dashboard(proc: psutil.Process | None) -> bool:
    if proc is None:
        return False
    try:
        cmdline = proc.cmdline()
    except psutil.Error:
        return False
    return "-m" in cmdline and "app" in cmdline and "serve" in cmdline


@pytest.fixture
def jupyter(ros_env, tmp_path) -> Iterator[JupyterServer]:
    server = JupyterServer(ros_env, tmp_path / "home" / "learner1")
    try:
        yield server
    finally:
        server.stop()


def test_the_launcher_lists_the_classroom(jupyter):
    status, body = jupyter.get("/server-proxy/servers-info")
    assert status == 200, body
    servers = {entry["name"]: entry for entry in json.loads(body)["server_processes"]}
    entry = servers["ros2-classroom"]
    assert entry["launcher_entry"]["title"] == "ROS 2 Classroom"
    assert entry["launcher_entry"]["enabled"]
    # The icon is served: the launcher would show a broken image otherwise.
    status, icon = jupyter.get(entry["launcher_entry"]["icon_url"])
    assert status == 200 and b"<svg" in icon


def test_the_dashboard_works_under_the_proxy_and_only_through_it(jupyter, browser):
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    page = context.new_page()
    try:
        # First request starts the learner's dashboard (cold start: imports, DDS).
        page.goto(f"{jupyter.base}/ros2-classroom/?token={JUPYTER_TOKEN}", timeout=120_000)
        expect_text(page, "ros2 node list", timeout=60_000)  # the websocket is up: GUI drawn

        # A catalog node started from the page appears on the live graph.
        start_node(page, "talker")
        open_tab(page, "Graph")
        expect_text(page, "/talker", timeout=30_000)

        # Page links under the base path: a lifecycle edge in the drawing is a link
        # (classroom/act/...) that must reach the dashboard through the proxy.
        start_node(page, "lifecycle_talker")
        open_tab(page, "Lifecycle")
        expect_text(page, "Current state of /lifecycle_talker: unconfigured", timeout=30_000)
        edge = page.locator('g.live-edge a[aria-label^="configure:"]')
        expect(edge).to_have_count(1, timeout=20_000)
        with page.expect_request(re.compile(r"/ros2-classroom/classroom/act/")) as link:
            edge.locator("text").click()
        assert link.value.url.startswith(f"{jupyter.base}/ros2-classroom/classroom/act/")
        expect_text(page, "Current state of /lifecycle_talker: inactive")

        # The exercise editor's frame and its own websocket, under the base path.
        open_tab(page, "Exercise")
        choose(page, "Exercise", f"{EXERCISE.unit:02d} · {EXERCISE.title}")
        page.get_by_role("button", name="Open my code").click()  # the editor goes on stage
        page.get_by_role("tab", name="Your code").click()
        frame = page.frame_locator("iframe[src*='editor.html']")
        expect_editor_loaded(frame)
        editor_frame = page.frame(url=re.compile(r"/ros2-classroom/classroom/editor/editor\.html"))
        assert editor_frame is not None, [f.url for f in page.frames]

        # Learner files live in the learner's own home.
        home = Path(next(a for a in jupyter.proc.args if "root_dir" in a).split("=", 1)[1])
        assert (home / "ros2-classroom" / "progress").is_dir()

        # The dashboard's loopback port refuses whoever skips the proxy.
        (dashboard,) = jupyter.dashboards()
        port = int(dashboard.cmdline()[dashboard.cmdline().index("--port") + 1])
        with pytest.raises(urllib.error.HTTPError) as refused:
            urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=10)
        assert refused.value.code == 401
    finally:
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(ARTIFACTS / "hub-server-proxy.png"))
        context.close()
    # The node started from the page ends with the server (ros_env checks it after).
    jupyter.stop()
