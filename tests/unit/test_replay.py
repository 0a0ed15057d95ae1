"""A recording made ready to watch (app/bags/replay.py) and drawn (app/stage/replay_stage.py).

The bag is written here with rosbags' writer and rclpy's serializer (no DDS):
a robot driving along x for two trials (the world reset between them), its
scans of a wall ahead, the room's markers, and a topic the grader fed.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from rosbags.rosbag2 import StoragePlugin, Writer
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Int64
from visualization_msgs.msg import Marker, MarkerArray

from app.bags.definitions import definition
from app.bags.errors import BagError
from app.bags.replay import read_track
from app.stage.replay_stage import TopView, timeline_at, top_view_svg

START_NS = 1_000_000_000_000
WALL_X = 2.0  # the wall's face: a box from x=2.0 to 2.2


def _odom(x: float, y: float, yaw: float, sim: float = 0.0) -> Odometry:
    msg = Odometry()
    msg.header.stamp.sec, msg.header.stamp.nanosec = int(sim), int(round(sim % 1 * 1e9))
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
    msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return msg


def _scan(x: float) -> LaserScan:
    """Three rays: ahead (to the wall), one to each side (nothing: inf)."""
    msg = LaserScan()
    msg.angle_min, msg.angle_increment = -math.pi / 2, math.pi / 2
    msg.range_min, msg.range_max = 0.1, 10.0
    msg.ranges = [math.inf, WALL_X - x, math.inf]
    return msg


def _room() -> MarkerArray:
    floor, wall = Marker(), Marker()
    floor.ns, floor.id = "floor", 0
    floor.scale.x, floor.scale.y, floor.scale.z = 4.0, 4.0, 0.01
    wall.ns, wall.id = "walls", 1
    wall.pose.position.x, wall.pose.position.z = WALL_X + 0.1, 0.25
    wall.scale.x, wall.scale.y, wall.scale.z = 0.2, 4.0, 0.5
    for marker in (floor, wall):
        marker.pose.orientation.w = 1.0
    return MarkerArray(markers=[floor, wall])


def _write(path: Path, messages: list[tuple[str, float, object]], in_order: bool = True) -> Path:
    writer = Writer(path, version=8, storage_plugin=StoragePlugin.MCAP)
    connections = {}
    with writer:
        for topic, t, msg in sorted(messages, key=lambda m: m[1]) if in_order else messages:
            kind = type(msg).__module__.split(".")[0] + "/msg/" + type(msg).__name__
            if topic not in connections:
                msgdef, rihs01 = definition(kind)
                connections[topic] = writer.add_connection(
                    topic, kind, msgdef=msgdef, rihs01=rihs01
                )
            writer.write(connections[topic], START_NS + int(t * 1e9), serialize_message(msg))
    return path


@pytest.fixture
def drive_bag(tmp_path: Path) -> Path:
    messages: list[tuple[str, float, object]] = [("/sim_world/static_markers", 0.0, _room())]
    # Before the grader's first reset: the world where it started, for a moment.
    messages.append(("/ground_truth/odom", 0.001, _odom(0.0, -1.5, 0.0, 100.0)))
    for trial, t0 in enumerate((0.0, 5.0)):
        for step in range(40):  # 0.1 m a tenth of a second, from x=-1 (trial 2 from y=1)
            t, x = t0 + step * 0.1, -1.0 + step * 0.04
            sim = 2 * step * 0.1  # the world runs at twice real time, from 0 at each reset
            messages.append(("/ground_truth/odom", t + 0.01, _odom(x, float(trial), 0.0, sim)))
            messages.append(("/scan", t + 0.02, _scan(x)))
            messages.append(("/cmd_vel", t + 0.03, Twist()))
    messages.append(("/numbers", 9.0, Int64(data=41)))
    return _write(tmp_path / "attempt", messages)


def test_a_drive_is_read_as_poses_scans_the_room_and_the_other_messages(drive_bag):
    track = read_track(drive_bag)
    assert track.drives and track.pose_topic == "/ground_truth/odom"
    assert len(track.poses) == 81 and len(track.scans) == 80
    assert [box.name for box in track.room] == ["walls/1"]
    assert track.floor is not None and track.floor.half_x == pytest.approx(2.0)
    # The scan's ray straight ahead hits the wall's face, whatever the robot's x.
    for scan in track.scans:
        assert len(scan.points) == 1 and scan.points[0][0] == pytest.approx(WALL_X, abs=0.01)
    # /cmd_vel (not drawn) and /numbers are lines of text at their moments.
    assert track.moments[-1].topic == "/numbers" and '"data": 41' in track.moments[-1].text
    assert len(track.moments_until(9.5, 3)) == 3


def test_the_way_so_far_is_cut_where_the_world_was_reset(drive_bag):
    track = read_track(drive_bag)
    assert len(track.way_until(2.0)) == 1  # the moment before the first reset is no trial
    first, second = track.way_until(9.0)
    assert first[-1].y == 0.0 and second[0].y == 1.0
    # The trial's own clock: simulated seconds, twice the recording's here.
    assert track.trial_seconds(3.0) == pytest.approx(5.8, abs=0.01)  # the pose of 2.91 s
    assert track.trial_seconds(5.5) == pytest.approx(0.8, abs=0.01)
    pose = track.pose_at(5.52)
    assert pose is not None and pose.y == 1.0 and pose.x == pytest.approx(-1.0 + 5 * 0.04)
    assert track.pose_at(0.0) is None  # before the first pose
    assert track.trial_seconds(0.0) is None


def test_the_top_view_puts_the_robot_where_the_ground_truth_put_it(drive_bag):
    track = read_track(drive_bag)
    view = TopView.around(track)
    for t in (1.0, 3.0, 8.0):
        svg = top_view_svg(track, t, view)
        robot = re.search(r'id="replay-robot" data-x="([-\d.]+)" data-y="([-\d.]+)"', svg)
        truth = track.pose_at(t)
        assert robot and truth is not None
        assert (float(robot[1]), float(robot[2])) == pytest.approx((truth.x, truth.y), abs=1e-3)
        # The robot's circle is drawn at the pixel its pose maps to.
        cx, cy = view.px(truth.x, truth.y)
        assert f'cx="{cx:.1f}" cy="{cy:.1f}"' in svg
    assert svg.count("<polyline") == 2  # two trials, two lines
    assert 'class="replay-scan"' in svg and "walls/1" in svg


def test_messages_written_out_of_time_order_play_in_time_order(tmp_path):
    """The recorder writes a batch of one topic, then another's: the file is not in time
    order, and the poses must be (a robot drawn from a later pose jumps ahead)."""
    poses = [("/ground_truth/odom", t / 10, _odom(t / 10, 0.0, 0.0)) for t in range(20)]
    bag = _write(tmp_path / "shuffled", poses[10:] + poses[:10], in_order=False)
    track = read_track(bag)
    assert [p.t for p in track.poses] == sorted(p.t for p in track.poses)
    pose = track.pose_at(0.55)
    assert pose is not None and pose.x == pytest.approx(0.5)


def test_a_bag_without_a_robot_plays_as_a_timeline_with_a_cursor(tmp_path):
    bag = _write(tmp_path / "topics", [("/numbers", t, Int64(data=int(t))) for t in range(5)])
    track = read_track(bag)
    assert not track.drives and len(track.moments) == 5
    svg = timeline_at(track, 2.0)
    cursor = re.search(r'class="cursor" x1="([\d.]+)"', svg)
    assert cursor and "/numbers (5)" in svg
    ticks = [float(x) for x in re.findall(r'<line x1="([\d.]+)" y1="10"', svg)]
    assert float(cursor[1]) == pytest.approx(ticks[2], abs=0.2)  # at the third message (t=2 s)


def test_what_is_not_a_bag_is_one_clear_error(tmp_path):
    with pytest.raises(BagError, match="no bag at"):
        read_track(tmp_path / "missing")
    damaged = tmp_path / "damaged"
    damaged.mkdir()
    (damaged / "metadata.yaml").write_text("rosbag2_bagfile_information: [", encoding="utf-8")
    with pytest.raises(BagError):
        read_track(damaged)
