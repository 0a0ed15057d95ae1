"""``ros2-classroom foxglove``: starts, serves a real client, stops on Ctrl+C; refuses clearly."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from app import PROJECT_ROOT
from tests.conftest import free_port, run_cli, wait_until
from tests.foxglove.client import FoxgloveClient

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]


def test_the_command_serves_the_graph_and_stops_on_ctrl_c(ros_env, tmp_path: Path):
    port = free_port()
    log = tmp_path / "foxglove.log"
    with log.open("wb") as out:
        proc = subprocess.Popen(
            [sys.executable, "-m", "app", "foxglove", "--port", str(port)],
            cwd=PROJECT_ROOT,
            env={**ros_env, "PYTHONUNBUFFERED": "1"},
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    try:
        url = f"ws://127.0.0.1:{port}"
        wait_until(
            lambda: proc.poll() is not None or f"ready: {url}" in log.read_text(),
            timeout=40,
            what="the bridge to say its URL",
        )
        assert proc.poll() is None, log.read_text()
        client = FoxgloveClient(url)
        try:
            client.wait_for(lambda: client.server_info, 10, "serverInfo")
            # Its own node's /rosout is a topic of the graph like any other.
            client.wait_for(lambda: client.channel("/rosout"), 30, "the /rosout channel")
            assert client.channel("/rosout")["schemaName"] == "rcl_interfaces/msg/Log"
        finally:
            client.close()
        started = time.monotonic()
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=20) == 0, log.read_text()
        assert time.monotonic() - started < 15
        text = log.read_text()
        assert "Stopped in" in text and "Traceback" not in text, text
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_the_command_refuses_other_hosts_and_a_busy_port_in_one_line(ros_env):
    other = run_cli("foxglove", "--host", "0.0.0.0", env=ros_env)
    assert other.returncode == 2 and "refusing to serve on 0.0.0.0" in other.stderr
    assert "Traceback" not in other.stderr
    import socket

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        busy = run_cli("foxglove", "--port", str(taken.getsockname()[1]), env=ros_env)
    assert busy.returncode == 2 and "already in use" in busy.stderr, busy.stderr
    assert "Traceback" not in busy.stderr
