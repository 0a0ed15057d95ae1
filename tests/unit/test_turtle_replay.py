"""A turtlesim attempt made ready to watch (app/bags/replay.py) and drawn as turtlesim's window
(app/stage/replay_stage.py).

The bag is written here with rosbags' writer and rclpy's serializer (no DDS), as a
turtle_follow grading records it: each turtle's ``/<turtle>/pose`` at turtlesim's rate,
the leader teleported once, and the follower's ``cmd_vel`` (a line of text, not drawn).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from geometry_msgs.msg import Twist
from rclpy.serialization import serialize_message
from rosbags.rosbag2 import StoragePlugin, Writer
from turtlesim.msg import Pose

from app.bags.definitions import definition
from app.bags.replay import read_track
from app.stage.replay_stage import TopView, top_view_svg
from nodes.common.turtlesim_world import WORLD_SIZE

START_NS = 2_000_000_000_000
RATE = 62.5  # turtlesim's poses per second


def _pose(x: float, y: float, theta: float) -> Pose:
    return Pose(x=x, y=y, theta=theta)


@pytest.fixture
def turtle_bag(tmp_path: Path) -> Path:
    """turtle1 sits at the centre, then is teleported to (2, 9) at 1.0 s; turtle2 drives
    from (1, 1) along x at 1 m/s from the start; turtle2 publishes nothing before 0.2 s."""
    messages: list[tuple[str, float, object]] = []
    for i in range(int(2.0 * RATE)):
        t = i / RATE
        leader = _pose(5.544, 5.544, 0.0) if t < 1.0 else _pose(2.0, 9.0, 1.5)
        messages.append(("/turtle1/pose", t, leader))
        if t >= 0.2:
            messages.append(("/turtle2/pose", t + 0.001, _pose(1.0 + t, 1.0, 0.0)))
    messages.append(("/turtle2/cmd_vel", 0.5, Twist()))
    path = tmp_path / "turtle_attempt"
    writer = Writer(path, version=8, storage_plugin=StoragePlugin.MCAP)
    connections = {}
    with writer:
        for topic, t, msg in sorted(messages, key=lambda m: m[1]):
            kind = type(msg).__module__.split(".")[0] + "/msg/" + type(msg).__name__
            if topic not in connections:
                msgdef, rihs01 = definition(kind)
                connections[topic] = writer.add_connection(
                    topic, kind, msgdef=msgdef, rihs01=rihs01
                )
            writer.write(connections[topic], START_NS + int(t * 1e9), serialize_message(msg))
    return path


def test_a_turtlesim_bag_reads_as_its_turtles_poses(turtle_bag: Path) -> None:
    track = read_track(turtle_bag)
    assert track.world == "turtlesim" and track.drives
    assert not track.poses  # no robot
    assert sorted(track.turtles) == ["turtle1", "turtle2"]
    assert len(track.turtles["turtle1"]) == int(2.0 * RATE)
    # Poses are drawn, not listed; the follower's command is a line of text.
    assert [m.topic for m in track.moments] == ["/turtle2/cmd_vel"]

    # Before turtle2 was spawned only turtle1 is there; each turtle at its newest pose.
    assert list(track.turtles_at(0.1)) == ["turtle1"]
    now = track.turtles_at(0.5)
    assert now["turtle1"].x == pytest.approx(5.544)
    assert now["turtle2"].x == pytest.approx(1.0 + now["turtle2"].t - 0.001, abs=1e-6)
    assert now["turtle2"].t <= 0.5
    after = track.turtles_at(1.5)["turtle1"]
    assert (after.x, after.y, after.yaw) == pytest.approx((2.0, 9.0, 1.5))

    # The trail so far is every pose up to t, the teleport's jump included (the pen draws it).
    trail = track.trail_until("turtle1", 1.1)
    assert trail[-1].x == pytest.approx(2.0) and trail[0].x == pytest.approx(5.544)
    assert all(p.t <= 1.1 for p in trail)
    assert track.trail_until("turtle2", 0.1) == []
    assert track.trail_until("nobody", 1.0) == []


def test_a_turtlesim_bag_is_drawn_as_turtlesims_window(turtle_bag: Path) -> None:
    track = read_track(turtle_bag)
    view = TopView.around(track)
    # The 11.09 m square at the window's own 45 px a metre (500 px), on turtlesim's blue.
    assert view.width == pytest.approx(WORLD_SIZE * 45 + 20)
    svg = top_view_svg(track, 1.5, view)
    assert 'fill="#4556ff"' in svg  # (69, 86, 255)
    assert 'data-cursor="1.500"' in svg
    turtles = re.findall(r'class="replay-turtle" data-name="(\w+)" data-x="([\d.]+)"', svg)
    assert [(name, float(x)) for name, x in turtles] == [
        ("turtle1", 2.0),
        ("turtle2", pytest.approx(2.5, abs=0.02)),
    ]
    assert svg.count("<polyline") == 2  # a trail each, in colours of their own
    assert len(set(re.findall(r'<polyline[^>]*stroke="(#\w+)"', svg))) == 2
    # turtle1 at the window's top-left quarter: x 2 m -> 10 + 90 px, y 9 m -> up high.
    x, y = view.px(2.0, 9.0)
    assert x == pytest.approx(100.0) and y == pytest.approx(10 + (WORLD_SIZE - 9.0) * 45)
    # Before turtle2 existed: one turtle, and no trail of one pose.
    early = top_view_svg(track, 0.0, view)
    assert early.count('class="replay-turtle"') == 1 and "<polyline" not in early
