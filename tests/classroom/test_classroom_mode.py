"""Classroom mode: three learners, each on their own port, domain and progress; isolated.

A learner's dashboard that stops answering is started again; the others never notice.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
import urllib.request

import psutil
import pytest

from app import PROJECT_ROOT
from app.ros.liveness import LIMIT_VARIABLE
from tests.conftest import free_port, wait_until
from tests.wire_client import WireClient

pytestmark = pytest.mark.ros

LIVENESS_LIMIT_SEC = 6  # each dashboard's ROS guard: ended after this long without an answer


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
        cwd=PROJECT_ROOT, env={**ros_env, LIMIT_VARIABLE: str(LIVENESS_LIMIT_SEC)},
        stdout=subprocess.PIPE, text=True,
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

        # learner2's dashboard stops answering (SIGSTOP stands in for a hung DDS
        # participant, tests/faults/test_ros_liveness.py): its guard ends it, the
        # classroom starts it again, and learner1's talker never notices.
        stuck = _serving(base_port + 1)
        os.kill(stuck, signal.SIGSTOP)
        while "learner2's dashboard ended" not in lines[-1]:
            line = room.stdout.readline()
            assert line, f"classroom ended early: {lines}"
            lines.append(line)
        # However the guard's end came (SIGABRT, or SIGKILL when the abort takes too long
        # on a loaded machine), the classroom knows the guard did it, and restarts.
        assert "its guard ended it" in lines[-1] and "starting it again" in lines[-1], lines
        wait_until(lambda: _serving(base_port + 1) not in (None, stuck), timeout=60,
                   what="learner2's new dashboard")  # fmt: skip
        clients[1].close()
        clients[1] = WireClient(urls[1])
        wait_until(lambda: f"Domain id **{base_domain + 1}**" in clients[1].markdown(),
                   what="learner2's header again")  # fmt: skip
        assert "/talker" in _graph_nodes(clients[0])
        descendants = psutil.Process(room.pid).children(recursive=True)
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


def _serving(port: int) -> int | None:
    """The pid listening on ``port`` (a learner's dashboard, forked warm or started cold)."""
    for conn in psutil.net_connections("tcp"):
        if conn.status == psutil.CONN_LISTEN and conn.laddr.port == port and conn.pid:
            return conn.pid
    return None


def _busy(port: int) -> bool:
    import socket

    with socket.socket() as probe:
        try:
            probe.bind(("127.0.0.1", port))
        except OSError:
            return True
    return False
