"""sim_world over real DDS, judged from a separate plain-rclpy process (sim_client.py).

The launch group sim_drive (sim_world and the arrow-key teleop) starts under
the supervisor; the client imports only rclpy and message packages, runs from a
folder outside the project, and reports what it measured. Each test judges one
part against what a Gazebo user would expect of the robot's drivers.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from app import PROJECT_ROOT
from app.catalog import lookup_group
from tests.outside_report import part, private_dds_env, run_outside_client

# The module fixture runs every scenario at once (tests/outside_report.py: CLIENT_TIMEOUT_SEC).
# Alone: beside three browser workers the world's services took over 25 s to answer
# (its physics and software-rendered camera share the cores); alone all pass in 45 s.
pytestmark = [pytest.mark.ros, pytest.mark.timeout(420), pytest.mark.alone]

CLIENT = Path(__file__).with_name("sim_client.py")
ROOM_HALF = 2.0  # inner faces of the room's walls at x, y = +-2 m
LIDAR_NOISE = 0.01  # m, the scanner's standard deviation


@pytest.fixture(scope="module")
def env() -> dict[str, str]:
    return private_dds_env()


@pytest.fixture(scope="module")
def report(env, tmp_path_factory) -> dict:
    members = list(lookup_group("sim_drive").members)  # sim_world and the teleop
    folder = tmp_path_factory.mktemp("outside")
    return run_outside_client(env, folder, CLIENT, members, "sim_world", "sim")


def test_the_client_is_plain_rclpy_and_the_world_survived_everything(report):
    assert report["project_modules_imported"] == []
    assert report["node_alive_at_end"]
    assert not any("Traceback" in line for line in report["node_log"])


def test_sensors_publish_what_a_real_robot_publishes(report):
    start = part(report, "start")
    assert start["image"] == [320, 240, "rgb8", 320 * 240 * 3]
    assert start["info_k"][2] == 160.0 and start["info_k"][5] == 120.0
    count, angle_min, increment, frame = start["scan"]
    assert (count, frame) == (360, "lidar_link")
    assert angle_min == pytest.approx(-math.pi) and increment == pytest.approx(math.pi / 180)
    for joint in ("left_wheel_joint", "right_wheel_joint", "base_yaw", "wrist_pitch"):
        assert joint in start["joint_names"]
    assert ["world", "odom"] in start["tf"] and ["odom", "base_link"] in start["tf"]
    assert start["tf_static"] == ["world", "arm_base_link", [1.4, 1.4], True]  # room/world.xml
    # Rates in simulation time (header stamps): one scan each 0.1 s, no frame skipped
    # beyond what a busy renderer drops (the wall-clock side: the real-time factor).
    assert 9.5 <= start["rates"]["scan"] <= 10.5, start["rates"]
    assert 0.8 * 15 <= start["rates"]["camera"] <= 15.5, start["rates"]
    assert 0.8 <= start["rtf"] <= 1.2


def test_one_tf_tree_from_world_to_every_sensor_frame_and_world_odom_base_is_the_truth(report):
    tree = part(report, "frames")
    assert tree["chains"]["lidar_link"] == ["lidar_link", "base_link", "odom", "world"]
    assert tree["chains"]["camera_optical_frame"] == [
        "camera_optical_frame", "camera_link", "base_link", "odom", "world",
    ]  # fmt: skip
    assert tree["chains"]["left_wheel"][-3:] == ["base_link", "odom", "world"]
    assert tree["chains"]["tool_tip"] == [
        "tool_tip", "gripper_link", "forearm", "upper_arm", "turntable", "arm_base_link", "world",
    ]  # fmt: skip
    assert tree["headers"] == {
        "/scan": "lidar_link", "/camera/image_raw": "camera_optical_frame", "/imu": "imu_link",
    }  # fmt: skip
    assert all(tree["header_frames_known"].values())
    composed, truth = tree["composed_vs_truth"]
    assert math.dist(composed, truth) < 0.002, tree["composed_vs_truth"]
    assert tree["robot_names"] == {
        "/robot_description": ["diffbot"], "/arm/robot_description": ["arm"],
    }  # fmt: skip


def test_the_world_is_published_as_markers_from_the_same_model(report):
    tree = part(report, "frames")
    first, *shapes = tree["static_markers"]
    assert first[0] == 3  # DELETEALL: a world loaded before goes
    assert {m[1] for m in shapes} == {"world"} and {m[0] for m in shapes} == {0}
    walls = [m for m in shapes if m[3] == 1 and m[4][2] == pytest.approx(0.5)]  # CUBEs 0.5 m high
    assert sorted(round(abs(w[5][0]) + abs(w[5][1]), 2) for w in walls) == [2.05] * 4
    assert any(m[3] == 3 for m in shapes)  # the barrel, a CYLINDER
    assert not any(m[2] in ("base_link", "upper_arm") for m in shapes)  # robots: their URDFs
    (cube,) = tree["object_markers"]
    assert cube[:3] == ["cube", 1, "world"]
    assert cube[3] == pytest.approx([1.15, 1.15], abs=0.01)


def test_the_sim_drive_group_teleop_drives_the_robot_forward(report):
    teleop = part(report, "teleop")
    dx, dy = teleop["moved"]
    # 0.3 m/s while the key is held, and until the last command times out (0.5 s of
    # simulated time), give or take a /clock period at each end.
    most = 0.3 * (teleop["held_sim_sec"] + 0.5 + 0.1)
    assert 0.1 < dx < most and abs(dy) < 0.05, (dx, dy, teleop["held_sim_sec"])


def test_a_node_with_use_sim_time_follows_the_clock_and_stops_when_paused(report):
    sim = part(report, "sim_time")
    # The node's clock and the test's copy of /clock are two subscriptions of one process,
    # handled in turn: on a loaded CI machine they were up to 0.12 s apart (a wall clock
    # would be 1.8e9 s off).
    assert max(abs(offset) for offset in sim["offsets"]) < 0.3, sim["offsets"]
    assert sim["paused"][1] == sim["paused"][0] > 0.0


def test_the_scan_matches_the_walls_of_the_room_within_the_noise(report):
    scan = part(report, "scan_in_room")
    x, y = scan["truth"]
    assert math.hypot(x, y) < 0.01  # reset put the robot at the origin, facing +x
    angles = scan["angle_min"] + np.arange(360) * scan["increment"]
    ranges = np.array(scan["ranges"])
    # Expected: the nearest wall along each ray from the lidar (at the robot's origin).
    with np.errstate(divide="ignore"):
        to_x = np.where(
            np.cos(angles) != 0,
            (ROOM_HALF - np.sign(np.cos(angles)) * x) / np.abs(np.cos(angles)),
            np.inf,
        )
        to_y = np.where(
            np.sin(angles) != 0,
            (ROOM_HALF - np.sign(np.sin(angles)) * y) / np.abs(np.sin(angles)),
            np.inf,
        )
    expected = np.minimum(to_x, to_y)
    # Rays towards the objects (box at 135 deg, barrel at -56 deg, table at 45 deg) see them first.
    degrees = np.degrees(angles)
    free = np.ones(360, bool)
    for centre, half in ((135, 15), (-56, 9), (45, 16)):
        sector = np.abs((degrees - centre + 180) % 360 - 180) <= half
        assert ranges[sector].min() < expected[sector].min() - 0.3  # the object, not the wall
        free &= ~sector
    error = ranges[free] - expected[free]
    assert np.all(np.isfinite(ranges[free]))
    assert abs(np.mean(error)) < 0.005, np.mean(error)
    assert 0.5 * LIDAR_NOISE < np.std(error) < 2.0 * LIDAR_NOISE, np.std(error)
    assert np.max(np.abs(error)) < 5 * LIDAR_NOISE


def test_pause_holds_time_and_step_advances_it_exactly(report):
    step = part(report, "pause_and_step")
    assert step["still"] == pytest.approx(step["before"], abs=1e-9)
    assert step["step"][0], step["step"]
    assert step["after"] - step["still"] == pytest.approx(0.1, abs=0.011)
    assert not step["step_while_running"][0] and "pause" in step["step_while_running"][1]


def test_0_2_m_per_s_for_5_s_drives_1_m_and_odometry_drifts_a_little(report):
    drive = part(report, "drive")
    assert "to t=" in drive["step"]
    assert drive["truth"] == pytest.approx(1.0, rel=0.05), drive
    assert drive["odom"] == pytest.approx(drive["truth"], rel=0.05)
    assert drive["odom"] != drive["truth"]  # the driver's calibration is not the truth


def test_real_time_factor_runs_faster_and_the_command_times_out(report):
    """Asked for 3x (camera on), the world runs as fast as the computer lets it: 2.1x on
    loaded cores. What matters holds anyway: it reports what it achieved, /clock agrees
    with that report, and simulated time runs faster than the wall clock, never faster
    than asked."""
    fast = part(report, "fast_and_timeout")
    print(f"asked 3x: /clock {fast['measured']:.3f}x, reported {fast['reported']:.3f}x")
    assert fast["refused_negative"]
    assert fast["measured"] == pytest.approx(fast["reported"], rel=0.03), fast
    assert 1.0 < fast["measured"] <= 3.0 * 1.03, fast
    assert abs(fast["speed"]) < 0.01


def test_nan_and_huge_velocities_are_refused_or_clamped_and_the_world_goes_on(report):
    bad = part(report, "bad_velocities")
    assert bad["clock_advanced"] > 0.5
    assert bad["moved_after_nan"] < 0.005
    assert bad["nan_log"] and "non-finite" in bad["nan_log"][0]
    assert bad["clamp_log"] and "clamped" in bad["clamp_log"][0]
    assert 0.3 < bad["speed_under_huge"] <= 0.5 + 0.02


def test_a_joint_trajectory_is_reached_and_a_bad_one_refused_with_the_reason(report):
    arm = part(report, "arm")
    for name, goal in arm["goal"].items():
        assert arm["reached"][name] == pytest.approx(goal, abs=0.02), (name, arm["reached"])
    joined = "\n".join(arm["rejections"])
    assert "unknown joint name(s) ['shoulder']" in joined
    assert "3 positions for 4 joint names" in joined


def test_a_world_that_does_not_load_or_a_bad_parameter_stops_the_node_with_the_reason(
    env, tmp_path
):
    broken = tmp_path / "broken.xml"
    broken.write_text("<mujoco><worldbody><geom type='box'</worldbody></mujoco>")
    done = subprocess.run(
        [sys.executable, "-m", "nodes.sim_world", "--ros-args", "-p", f"world:={broken}"],
        cwd=PROJECT_ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 2, done.stderr
    assert f"sim_world: error: world file {broken} does not load: XML parse error" in done.stderr
    assert "Traceback" not in done.stderr
    missing = subprocess.run(
        [sys.executable, "-m", "nodes.sim_world", "--ros-args", "-p", "world:=no_such_world"],
        cwd=PROJECT_ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert missing.returncode == 2
    assert "does not exist (worlds under nodes/worlds: office, room)" in missing.stderr
    ticks = subprocess.run(
        [sys.executable, "-m", "nodes.sim_world", "--ros-args", "-p", "encoder_ticks:=0"],
        cwd=PROJECT_ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert ticks.returncode == 2
    assert "sim_world: error: parameter encoder_ticks = 0 is outside 1..1048576" in ticks.stderr
