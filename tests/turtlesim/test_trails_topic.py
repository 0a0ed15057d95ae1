"""The hidden trails topic a viewer draws from: segments as the turtle draws, the whole
picture on request (a view opened late) and after /clear, and hidden from `ros2 topic list`.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest
from geometry_msgs.msg import Twist
from std_msgs.msg import Empty, UInt8MultiArray
from std_srvs.srv import Empty as EmptySrv

from app.ros.graph import snapshot
from nodes.common.turtlesim_world import (
    DEFAULT_PEN,
    PIXELS,
    SEGMENTS,
    SNAPSHOT,
    TrailsPacket,
    decode_trails,
    paint_segment,
)
from nodes.turtlesim_node import TOPIC_QOS, TRAILS_QOS
from tests.conftest import wait_until
from tests.integration.core_helpers import DISCOVERY_TIMEOUT, call_service, node_names

pytestmark = pytest.mark.ros


class TrailsWatcher:
    def __init__(self, node) -> None:
        self.lock = threading.Lock()
        self.packets: list[TrailsPacket] = []
        node.create_subscription(UInt8MultiArray, "/turtlesim/_trails", self.on_packet, TRAILS_QOS)

    def on_packet(self, msg: UInt8MultiArray) -> None:
        with self.lock:
            self.packets.append(decode_trails(bytes(msg.data)))

    def since(self, count: int) -> list[TrailsPacket]:
        with self.lock:
            return self.packets[count:]

    def __len__(self) -> int:
        with self.lock:
            return len(self.packets)


def test_segments_then_snapshot_on_request_and_after_clear(supervisor, probe):
    supervisor.start("turtlesim_node")
    wait_until(lambda: "/turtlesim" in node_names(probe), timeout=DISCOVERY_TIMEOUT)
    watcher = TrailsWatcher(probe.node)
    # Transient local: the start-up snapshot (nothing drawn yet) reaches a late joiner.
    first = wait_until(lambda: watcher.since(0), timeout=DISCOVERY_TIMEOUT, what="a packet")[0]
    assert first.kind == SNAPSHOT and first.start == 0 and first.painted is not None
    assert not first.painted.any()

    drive = probe.node.create_publisher(Twist, "/turtle1/cmd_vel", TOPIC_QOS)
    wait_until(lambda: drive.get_subscription_count() > 0, what="turtlesim's cmd_vel")
    twist = Twist()
    twist.linear.x, twist.angular.z = 2.0, 1.0
    drive.publish(twist)
    wait_until(lambda: sum(len(p.segments) for p in watcher.since(1)) >= 40, what="40 segments")
    moved = watcher.since(1)
    # Segments follow each other without a gap, in the default pen.
    index = first.start
    canvas = np.zeros((PIXELS, PIXELS, 3), np.uint8)
    painted = np.zeros((PIXELS, PIXELS), bool)
    for packet in moved:
        assert packet.kind == SEGMENTS and packet.session == first.session
        assert packet.start == index
        index += len(packet.segments)
        for segment in packet.segments:
            assert segment.color == DEFAULT_PEN and segment.width == 3
            paint_segment(canvas, painted, segment)

    # A viewer that asks gets the whole picture, which holds every segment it saw.
    seen = len(watcher)
    ask = probe.node.create_publisher(Empty, "/turtlesim/_trails_request", 10)
    wait_until(lambda: ask.get_subscription_count() > 0, what="the request subscription")
    ask.publish(Empty())
    whole = wait_until(
        lambda: next((p for p in watcher.since(seen) if p.kind == SNAPSHOT), None),
        what="a snapshot",
    )
    assert whole.session == first.session and whole.start >= index
    assert whole.painted is not None and whole.painted[painted].all()

    # /clear: an empty snapshot with the next clear count.
    seen = len(watcher)
    call_service(probe, EmptySrv, "/clear", EmptySrv.Request())
    cleared = wait_until(
        lambda: next((p for p in watcher.since(seen) if p.kind == SNAPSHOT), None),
        what="the snapshot after /clear",
    )
    assert cleared.clear_count == first.clear_count + 1
    # Hidden, as ros2cli hides names with a '_' token.
    names = [t.name for t in snapshot(probe.node).topics]
    assert "/turtle1/pose" in names and "/turtlesim/_trails" not in names
