"""Physics sanity of the MuJoCo world, without ROS: SimEngine and its helpers, in sim time."""

from __future__ import annotations

import logging
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from app import PROJECT_ROOT
from nodes.common.arm_kinematics import JOINT_NAMES, inverse_kinematics
from nodes.common.sim.assets import ROBOTS_DIR, WorldError, load_world, world_names
from nodes.common.sim.camera import SnapshotCamera, choose_gl_backend, intrinsics
from nodes.common.sim.diff_drive import (
    Odometry,
    check_twist,
    odom_in_world,
    quantize,
    wheel_speeds,
)
from nodes.common.sim.engine import Pose2D, SimEngine
from nodes.common.sim.trajectory import TrajectoryError, check_trajectory
from nodes.common.sim.world_geometry import WorldGeometry

LIMITS = {name: (-math.pi, math.pi) for name in JOINT_NAMES}

# A teacher's world, written without code: a 3 m x 2 m box room with the diffbot only.
BOX_ROOM = f"""
<mujoco model="box_room">
  <option timestep="0.002" integrator="implicitfast"/>
  <asset><model name="diffbot" file="{ROBOTS_DIR / "diffbot" / "robot.xml"}"/></asset>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    <geom type="box" size="0.05 1.1 0.3" pos="1.55 0 0.3"/>
    <geom type="box" size="0.05 1.1 0.3" pos="-1.55 0 0.3"/>
    <geom type="box" size="1.6 0.05 0.3" pos="0 1.05 0.3"/>
    <geom type="box" size="1.6 0.05 0.3" pos="0 -1.05 0.3"/>
    <frame><attach model="diffbot" body="base_link" prefix=""/></frame>
  </worldbody>
</mujoco>
"""


@pytest.fixture(scope="module")
def room() -> SimEngine:
    return SimEngine("room", drive_radius=0.0332, drive_separation=0.163)


@pytest.fixture
def box_room(tmp_path) -> str:
    path = tmp_path / "box_room.xml"
    path.write_text(BOX_ROOM)
    return str(path)


def test_0_2_m_per_s_for_5_s_of_sim_time_moves_1_m_by_ground_truth(room):
    room.reset(Pose2D(0.0, 0.0, 0.0))
    start = room.base_pose()[0]
    room.drive(0.2, 0.0)
    room.step(round(5.0 / room.timestep))
    room.drive(0.0, 0.0)
    assert room.time == pytest.approx(5.0)
    moved = room.base_pose()[0] - start
    assert math.hypot(moved[0], moved[1]) == pytest.approx(1.0, rel=0.05)
    assert abs(moved[1]) < 0.02 and abs(room.base_yaw()) < 0.02  # straight ahead


def test_odometry_from_the_encoders_drifts_from_the_truth_while_turning(room):
    room.reset(Pose2D(-0.5, -0.5, 0.3))
    odom = Odometry(0.0332, 0.163)
    odom.reset(*(quantize(a, 4096) for a in room.encoders()))
    start, yaw0 = room.base_pose()[0], room.base_yaw()
    room.drive(0.2, 0.6)
    for _ in range(150):  # 6 s at 25 Hz
        room.step(20)
        odom.update(*(quantize(a, 4096) for a in room.encoders()), dt=0.04)
    moved = room.base_pose()[0] - start
    local = (
        np.array(  # the truth, in the frame the robot started in (odom's frame)
            [[math.cos(yaw0), math.sin(yaw0)], [-math.sin(yaw0), math.cos(yaw0)]]
        )
        @ moved[:2]
    )
    error = math.hypot(local[0] - odom.x, local[1] - odom.y)
    assert 0.002 < error < 0.2, error  # close, never exact
    turned = (room.base_yaw() - yaw0 + math.pi) % (2 * math.pi) - math.pi
    assert odom.yaw == pytest.approx(turned, abs=0.25)
    assert odom.yaw != pytest.approx(turned, abs=1e-4)


def test_a_scan_in_a_known_room_matches_its_walls_within_the_noise(box_room):
    engine = SimEngine(box_room, start=Pose2D(0.3, -0.2, 0.5))
    assert engine.has_mobile and not engine.has_arm
    lidar = engine.lidar
    assert lidar is not None
    ranges = lidar.measure(engine.data)
    origin = engine.data.site_xpos[lidar.site_id]
    heading = engine.base_yaw() + lidar.angles
    c, s = np.cos(heading), np.sin(heading)
    with np.errstate(divide="ignore", invalid="ignore"):
        to_x = np.where(c > 0, (1.5 - origin[0]) / c, (-1.5 - origin[0]) / c)
        to_y = np.where(s > 0, (1.0 - origin[1]) / s, (-1.0 - origin[1]) / s)
    expected = np.minimum(np.where(to_x > 0, to_x, np.inf), np.where(to_y > 0, to_y, np.inf))
    error = ranges - expected
    assert len(ranges) == 360 and np.all(np.isfinite(ranges))
    assert abs(error.mean()) < 0.004
    assert 0.007 < error.std() < 0.014  # the 0.01 m noise, and nothing more
    assert np.abs(lidar.true_ranges(engine.data) - expected).max() < 1e-4  # 0.1 mm: tilt


def test_a_joint_trajectory_is_reached_within_tolerance(room):
    room.reset()
    goal = [0.8, 0.5, -1.0, -0.8]
    room.command_trajectory(list(JOINT_NAMES), [([0.4, 0.7, -1.4, -0.6], 1.0), (goal, 2.0)])
    room.step(round(1.0 / room.timestep))
    halfway = room.arm_positions()
    assert halfway[0] == pytest.approx(0.4, abs=0.05)  # it follows the waypoints in time
    room.step(round(1.5 / room.timestep))
    assert np.abs(room.arm_positions() - goal).max() < 0.01


def test_the_grasped_cube_moves_with_the_gripper(room):
    room.reset()
    reach = math.hypot(1.15 - 1.4, 1.15 - 1.4)  # the cube, seen from the arm's base

    def move_to(height: float) -> None:
        joints = inverse_kinematics((reach, 0.0, height))
        room.command_trajectory(list(JOINT_NAMES), [(list(joints), 1.5)])
        room.step(round(2.0 / room.timestep))

    cube0 = room.body_position("cube")
    move_to(0.15)
    move_to(0.012)
    room.set_gripper(0.0)
    room.step(round(1.0 / room.timestep))
    gripped = room.body_position("cube") - room.tool_position()
    move_to(0.25)
    lifted = room.body_position("cube")
    assert lifted[2] - cube0[2] > 0.2  # off the table with the arm
    assert np.abs(lifted - room.tool_position() - gripped).max() < 0.01  # held, not dropped
    room.set_gripper(0.09)  # let go: it falls back onto the table
    room.step(round(1.0 / room.timestep))
    assert room.body_position("cube")[2] == pytest.approx(cube0[2], abs=0.01)


def test_nan_velocities_are_rejected_and_huge_ones_clamped_with_the_reason():
    nan = check_twist(float("nan"), 0.0, 0.5, 2.5)
    assert nan.rejected and "non-finite" in nan.problem
    huge = check_twist(1e9, -50.0, 0.5, 2.5)
    assert not huge.rejected and (huge.linear, huge.angular) == (0.5, -2.5)
    assert "clamped" in huge.problem
    fine = check_twist(0.2, 0.1, 0.5, 2.5)
    assert (fine.linear, fine.angular, fine.problem) == (0.2, 0.1, "")
    left, right = wheel_speeds(0.2, 1.0, 0.033, 0.16)
    assert (left, right) == pytest.approx(((0.2 - 0.08) / 0.033, (0.2 + 0.08) / 0.033))


@pytest.mark.parametrize(
    ("names", "points", "reason"),
    [
        (["base_yaw", "shoulder"], [([0.0, 0.0], 1.0)], "unknown joint name(s) ['shoulder']"),
        (["base_yaw", "base_yaw"], [([0.0, 0.0], 1.0)], "joint names repeat"),
        (["base_yaw", "elbow_pitch"], [([0.0], 1.0)], "1 positions for 2 joint names"),
        (["base_yaw"], [([float("nan")], 1.0)], "non-finite"),
        (["base_yaw"], [([0.1], 1.0), ([0.2], 0.5)], "must increase"),
        (["base_yaw"], [([4.0], 1.0)], "outside its limits"),
        ([], [], "no joint names"),
    ],
)
def test_a_bad_trajectory_is_refused_with_the_reason(names, points, reason):
    with pytest.raises(TrajectoryError) as caught:
        check_trajectory(names, points, JOINT_NAMES, LIMITS, [0.0] * 4)
    assert reason in str(caught.value)


def test_a_world_that_does_not_parse_or_exist_is_refused_with_the_reason(tmp_path):
    broken = tmp_path / "broken.xml"
    broken.write_text("<mujoco><worldbody><geom type='box'</worldbody></mujoco>")
    with pytest.raises(WorldError, match=f"world file {broken} does not load: XML parse error"):
        load_world(str(broken))
    unknown = tmp_path / "unknown.xml"
    unknown.write_text("<mujoco><worldbody><geom type='doughnut'/></worldbody></mujoco>")
    with pytest.raises(WorldError, match="doughnut"):
        load_world(str(unknown))
    with pytest.raises(
        WorldError, match=r"does not exist \(worlds under nodes/worlds: office, room\)"
    ):
        load_world("atlantis")
    with pytest.raises(WorldError, match="neither a world name"):
        load_world("../../etc/passwd")
    assert "room" in world_names()


def test_the_camera_renders_the_room_headless():
    assert choose_gl_backend({"MUJOCO_GL": "osmesa"}) == "osmesa"  # a user's choice is kept
    env: dict[str, str] = {}
    assert choose_gl_backend(env) in ("egl", "osmesa") and env["MUJOCO_GL"]
    k = intrinsics(320, 240, 60.0)
    assert k[0, 0] == pytest.approx(120 / math.tan(math.radians(30)))
    engine = SimEngine("room")
    camera = SnapshotCamera(engine.model, "camera", 320, 240)
    try:
        image = camera.render(engine.snapshot())
    finally:
        camera.close()
    assert image.shape == (240, 320, 3)
    assert image.std() > 10  # walls, floor and objects, not a blank frame


def test_odometry_integrates_encoder_angles_exactly_on_a_straight_line_and_an_arc():
    odom = Odometry(radius=0.05, separation=0.2)
    odom.reset(0.0, 0.0)
    odom.update(10.0, 10.0, dt=1.0)  # both wheels 10 rad: 0.5 m straight ahead
    assert (odom.x, odom.y, odom.yaw) == pytest.approx((0.5, 0.0, 0.0))
    assert odom.linear == pytest.approx(0.5)
    odom.reset(0.0, 0.0)
    turn = math.pi / 2  # right wheel further: a quarter circle to the left of radius 0.5 m
    left, right = (0.5 - 0.1) * turn / 0.05, (0.5 + 0.1) * turn / 0.05
    for k in range(1, 101):
        odom.update(left * k / 100, right * k / 100, dt=0.01)
    assert (odom.x, odom.y, odom.yaw) == pytest.approx((0.5, 0.5, turn), abs=1e-6)
    assert quantize(0.0015, 4096) == 0.0 and quantize(0.0016, 4096) == pytest.approx(
        2 * math.pi / 4096
    )


def test_the_gripper_opening_is_clamped_to_what_the_fingers_can_do(room):
    room.reset()
    assert room.set_gripper(0.5) == 0.09
    assert room.set_gripper(-1.0) == 0.0
    assert room.set_gripper(0.04) == 0.04
    room.step(round(0.5 / room.timestep))
    names, positions, _ = room.joint_state()
    fingers = [positions[names.index(n)] for n in ("left_finger_joint", "right_finger_joint")]
    assert fingers == pytest.approx([0.02, 0.02], abs=0.002)


# A teacher's world with a mesh, a capsule on a body welded to the world (a lamp post),
# a loose ball, and geoms the viewer hides (group 3) or that are invisible.
SHAPES_ROOM = f"""
<mujoco model="shapes">
  <asset>
    <model name="diffbot" file="{ROBOTS_DIR / "diffbot" / "robot.xml"}"/>
    <mesh name="wedge" vertex="0 0 0  0.2 0 0  0 0.2 0  0 0 0.2"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 0.1" rgba="0.3 0.3 0.3 1"/>
    <geom name="wedge" type="mesh" mesh="wedge" pos="1 0 0" rgba="0 0 1 1"/>
    <geom name="hidden" type="box" size="0.1 0.1 0.1" group="3"/>
    <geom name="glass" type="box" size="0.1 0.1 0.1" rgba="1 1 1 0"/>
    <body name="lamp" pos="-1 0 0">
      <geom name="post" type="capsule" fromto="0 0 0 0 0 1" size="0.05"/>
    </body>
    <body name="ball" pos="0 1 0.1">
      <freejoint/>
      <geom name="ball" type="sphere" size="0.1" rgba="1 0 0 1"/>
    </body>
    <frame><attach model="diffbot" body="base_link" prefix=""/></frame>
  </worldbody>
</mujoco>
"""


def test_the_world_geometry_splits_static_objects_and_robots_into_markers(tmp_path):
    import mujoco  # here: MUJOCO_GL is set when nodes.common.sim is imported, before mujoco

    path = tmp_path / "shapes.xml"
    path.write_text(SHAPES_ROOM)
    engine = SimEngine(str(path))
    world = WorldGeometry(engine.model, ["base_link"])
    static = world.static_primitives(engine.data)
    by_ns: dict[str, list] = {}
    for shape in static:
        by_ns.setdefault(shape.ns, []).append(shape)
    assert sorted(by_ns) == ["lamp", "world"]  # no robot link, no hidden or invisible geom
    floor, wedge = by_ns["world"]
    assert floor.kind == "cube" and floor.scale == pytest.approx((20.0, 20.0, 0.01))
    assert floor.position[2] == pytest.approx(-0.007)  # top just under z = 0
    assert wedge.kind == "triangles" and wedge.triangles is not None
    assert wedge.triangles.shape == (12, 3)  # 4 faces of 3 corners, in the geom's frame
    assert wedge.rgba == (0.0, 0.0, 1.0, 1.0)
    post, top, bottom = by_ns["lamp"]  # a capsule: a cylinder and two end spheres
    assert (post.kind, top.kind, bottom.kind) == ("cylinder", "sphere", "sphere")
    assert post.scale == pytest.approx((0.1, 0.1, 1.0)) and post.position[2] == pytest.approx(0.5)
    assert sorted([top.position[2], bottom.position[2]]) == pytest.approx([0.0, 1.0])
    assert len({s.id for s in static}) == len(static)
    (ball,) = world.object_primitives(engine.data)
    assert (ball.ns, ball.kind, ball.scale) == ("ball", "sphere", pytest.approx((0.2,) * 3))
    assert world.objects_moved(engine.data)  # the first look: send them
    engine.step(10)
    assert not world.objects_moved(engine.data)  # resting on the floor: nothing to resend
    ball_x = engine.model.jnt_qposadr[engine.model.body("ball").jntadr[0]]
    engine.data.qpos[ball_x] += 0.05  # pushed 5 cm along x
    mujoco.mj_kinematics(engine.model, engine.data)
    assert world.objects_moved(engine.data)


def test_the_room_floor_takes_the_colour_of_its_checker_texture(room):
    world = WorldGeometry(room.model, ["base_link", "arm_base_link"])
    floor = room.model.geom("floor").id
    r, g, b, a = world.rgba(floor)
    assert (r, g, b) == pytest.approx((0.675, 0.675, 0.65), abs=0.01)  # between its 2 colours
    names = {room.model.geom(g).name for g in world.static_geoms}
    assert {"wall_east", "box", "barrel", "table"} <= names and "arm_pedestal" not in names
    assert [room.model.geom(g).name for g in world.object_geoms] == ["cube"]


def test_world_to_odom_makes_the_chain_to_base_link_the_truth():
    yaw = 1.0
    truth_q = (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
    position, quat = odom_in_world((1.0, 2.0, 0.01), truth_q, 0.9, 2.1, 0.8)
    x, y, z, w = quat
    correction = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    assert correction == pytest.approx(yaw - 0.8)
    c, s = math.cos(correction), math.sin(correction)
    back = (position[0] + c * 0.9 - s * 2.1, position[1] + s * 0.9 + c * 2.1, position[2])
    assert back == pytest.approx((1.0, 2.0, 0.01))
    assert odom_in_world((0.5, 0.5, 0.0), (0, 0, 0, 1), 0.5, 0.5, 0.0) == (
        pytest.approx((0.0, 0.0, 0.0)),
        pytest.approx((0.0, 0.0, 0.0, 1.0)),
    )  # odometry that is right: world and odom coincide


def test_egl_that_loads_but_makes_no_context_falls_back_to_osmesa():
    env: dict[str, str] = {}
    assert choose_gl_backend(env, egl_works=lambda: False) == "osmesa"
    assert env == {"MUJOCO_GL": "osmesa", "PYOPENGL_PLATFORM": "osmesa"}
    # For real: libEGL loads, but with no vendor library it finds no device to render on.
    clean = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    script = (
        "from nodes.common.sim import GL_BACKEND\n"
        "from nodes.common.sim.camera import SnapshotCamera\n"
        "from nodes.common.sim.engine import SimEngine\n"
        "engine = SimEngine('room')\n"
        "camera = SnapshotCamera(engine.model, 'camera', 64, 48)\n"
        "print(GL_BACKEND, camera.render(engine.snapshot()).std() > 10)\n"
        "camera.close()\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script],
        env={**clean, "__EGL_VENDOR_LIBRARY_FILENAMES": "/nonexistent/egl_vendor.json"},
        cwd=PROJECT_ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["osmesa", "True"]


def test_mujoco_warnings_go_to_the_log_and_never_to_a_file(tmp_path, monkeypatch, caplog):
    import mujoco

    monkeypatch.chdir(tmp_path)
    engine = SimEngine("room")
    engine.data.qvel[0] = float("nan")
    with caplog.at_level(logging.WARNING, logger="mujoco"):
        mujoco.mj_step(engine.model, engine.data)
    assert any("MuJoCo: Nan, Inf or huge value in QVEL" in r.message for r in caplog.records)
    assert list(tmp_path.iterdir()) == []  # no MUJOCO_LOG.TXT
