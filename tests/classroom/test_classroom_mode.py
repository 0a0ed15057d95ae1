"""Classroom mode: three learners, each on their own port, domain and progress; isolated."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import time
import urllib.request

import psutil
import pytest

from app import PROJECT_ROOT
from tests.conftest import free_port, wait_until
from tests.wire_client import WireClient

pytestmark = pytest.mark.ros


def _graph_nodes(client: WireClient) -> list[str]:
    return client.graph_nodes()


def test_three_isolated_learners(ros_env, tmp_path):
    base_port = free_port()
    while any(_busy(base_port + i) for i in range(3)):
        base_port = free_port()
    base_domain = int(ros_env["ROS_DOMAIN_ID"]) % 90 + 1
    room = subprocess.Popen(
        [sys.executable, "-m", "app", "classroom", "--learners", "3",
         "--base-port", str(base_port), "--base-domain-id", str(base_domain),
         "--progress-dir", str(tmp_path)],
        cwd=PROJECT_ROOT, env=ros_env, stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    clients: list[WireClient] = []
    try:
        lines = []
        while not lines or "Press Ctrl+C" not in lines[-1]:
            line = room.stdout.readline()
            assert line, f"classroom ended early: {lines}"
            lines.append(line)
        urls = re.findall(r"(http://127\.0\.0\.1:\d+)", "".join(lines))
        assert urls == [f"http://127.0.0.1:{base_port + i}" for i in range(3)], lines
        assert all(f"ROS domain {base_domain + i}" in "".join(lines) for i in range(3))
        for i, url in enumerate(urls):
            with urllib.request.urlopen(url, timeout=10) as page:
                assert page.status == 200
            client = WireClient(url)
            clients.append(client)
            wait_until(
                lambda c=client, i=i: f"Domain id **{base_domain + i}**" in c.markdown(),
                what=f"learner{i + 1}'s header",
            )
        # learner1 starts a talker; only learner1's dashboard may ever see it.
        wait_until(lambda: clients[0].find("Start", "GuiButtonMessage"), what="Nodes panel")
        clients[0].click("Start")
        wait_until(lambda: "/talker" in _graph_nodes(clients[0]), timeout=30, what="/talker")
        wait_until(lambda: _graph_nodes(clients[1]), what="learner2's graph")

        time.sleep(4.0)  # past Fast DDS's late-joiner heartbeat: a leak would show by now
        for client in clients:
            seen = _graph_nodes(client)
            assert seen.count("/classroom_dashboard") == 1, seen  # never another learner's
        assert "/talker" not in _graph_nodes(clients[1]) + _graph_nodes(clients[2])
        descendants = psutil.Process(room.pid).children(recursive=True)
        assert len(descendants) >= 4  # three dashboards and learner1's talker
    finally:
        for client in clients:
            client.close()
        room.send_signal(signal.SIGINT)
        code = room.wait(timeout=30)
    assert code == 0
    assert not [p for p in descendants if p.is_running() and p.status() != psutil.STATUS_ZOMBIE]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["learner1", "learner2", "learner3"] or (
        not list(tmp_path.iterdir())  # progress is written on the first lesson action
    )


def _busy(port: int) -> bool:
    import socket

    with socket.socket() as probe:
        try:
            probe.bind(("127.0.0.1", port))
        except OSError:
            return True
    return False
