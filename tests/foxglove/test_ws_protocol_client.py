"""Lichtblick's client library against the bridge: @foxglove/ws-protocol's FoxgloveClient
(from npm, run by Node, offering only "foxglove.websocket.v1") subscribes to a topic and
receives its CDR messages, and publishes on ROS (a teleop's path)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from tests.conftest import wait_until

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

CLIENT = Path(__file__).parent / "wsclient"


def test_the_client_lichtblick_is_built_on_subscribes_and_publishes(probe):
    from rclpy.serialization import deserialize_message, serialize_message
    from std_msgs.msg import String

    from app.foxglove import FoxgloveBridge

    node = shutil.which("node")
    assert node, "Node.js is needed (make setup installs npm, which brings it)"
    assert (CLIENT / "node_modules" / "@foxglove" / "ws-protocol").is_dir(), "run make setup"
    publisher = probe.node.create_publisher(String, "/lichtblick_in", 10)
    timer = probe.node.create_timer(0.05, lambda: publisher.publish(String(data="to the app")))
    heard: list[str] = []
    probe.node.create_subscription(String, "/lichtblick_out", lambda m: heard.append(m.data), 10)
    bridge = FoxgloveBridge(probe.node, port=0)
    bridge.start()
    try:
        payload = serialize_message(String(data="from the app")).hex()
        run = subprocess.run(
            [node, "client.js", bridge.url, "/lichtblick_in", "/lichtblick_out", payload],
            cwd=CLIENT,
            capture_output=True,
            text=True,
            timeout=60,
        )
        events = {e["event"]: e for e in map(json.loads, run.stdout.splitlines())}
        assert run.returncode == 0, (run.stdout, run.stderr)
        info = events["serverInfo"]
        assert info["protocol"] == "foxglove.websocket.v1"
        assert "clientPublish" in info["capabilities"]
        assert events["subscribed"]["schemaName"] == "std_msgs/msg/String"
        assert events["subscribed"]["encoding"] == "cdr"
        got = deserialize_message(bytes.fromhex(events["messages"]["last"]), String)
        assert got.data == "to the app"
        wait_until(lambda: heard, 10, what="the app's message on ROS")
        assert heard[-1] == "from the app"
    finally:
        bridge.close()
        probe.node.destroy_timer(timer)
