"""The "Drive a robot" lesson and what its checks and probes measure with: the world's floor plan.

The floor plan is read from the same MJCF file the simulation
loads; its distances are checked here against the room's known geometry
(nodes/worlds/room/world.xml: inner wall faces at +-2 m).
"""

from __future__ import annotations

import math
import random
import textwrap

import pytest

from app.lessons.checks._world_map import (
    Circle,
    Nearest,
    WorldMapError,
    _polygon_distance,
    _polygon_point_distance,
    footprint,
    load_world_map,
)
from app.lessons.kinds import CHECK_KINDS
from app.lessons.schema import LessonError, parse_spec
from tests.course_data import shared_course

SIM_KINDS = {"robot_moved", "odom_drift", "scan_nearest", "sim_time_stamps", "sim_paused"}


def test_the_unit_uses_every_simulation_check_kind():
    lesson = shared_course().lesson("19_wheeled_robot")
    assert lesson is not None
    used = {check.kind for step in lesson.steps for check in step.checks}
    assert SIM_KINDS <= used and SIM_KINDS <= set(CHECK_KINDS)


@pytest.mark.parametrize(
    ("raw", "error"),
    [
        ({"kind": "robot_moved"}, "needs field 'at_least'"),
        ({"kind": "odom_drift", "at_least": 1, "far": 2}, "unknown field 'far'"),
        ({"kind": "scan_nearest", "below": 0.5}, "needs field 'tolerance'"),
        ({"kind": "sim_time_stamps"}, "needs field 'frame'"),
        ({"kind": "sim_paused", "frames": "a"}, "unknown field 'frames'"),
    ],
)
def test_a_simulation_check_with_a_wrong_field_is_a_clear_error(raw, error):
    with pytest.raises(LessonError, match=error):
        parse_spec(raw, CHECK_KINDS, "lesson.toml: steps[0].checks[0]")


def test_the_room_plan_has_its_walls_and_objects_and_leaves_out_what_moves():
    plan = load_world_map("room")
    assert set(plan.names()) == {
        "wall_east",
        "wall_west",
        "wall_north",
        "wall_south",
        "box",
        "barrel",
        "table",
    }  # fmt: skip  (the cube has a joint, the floor is a plane, the robots are attached)
    assert plan.skipped == ()


@pytest.mark.parametrize("world", ["room", "office"])
def test_clearance_measures_only_what_can_be_closest_and_finds_what_measuring_all_does(world):
    plan = load_world_map(world)
    rng = random.Random(3)

    def every_obstacle(x: float, y: float, yaw: float) -> Nearest:
        body, best = footprint(x, y, yaw), Nearest(math.inf, "")
        for o in plan.obstacles:
            if isinstance(o, Circle):
                d = _polygon_point_distance(body, (o.x, o.y)) - o.radius
            else:
                d = _polygon_distance(body, o.corners())
            if d < best.distance:
                best = Nearest(d, o.name)
        return best

    # Poses all over the plan, many touching or inside furniture and walls.
    poses = [(rng.uniform(-6, 6), rng.uniform(-5, 5), rng.uniform(-4, 4)) for _ in range(1500)]
    assert [plan.clearance(*pose) for pose in poses] == [every_obstacle(*p) for p in poses]


def test_distances_rays_and_clearance_in_the_room():
    plan = load_world_map("room")
    assert plan.ray(0.0, 0.0, 0.0).distance == pytest.approx(2.0)
    assert plan.ray(0.0, 0.0, 0.0).name == "wall_east"
    assert plan.ray(0.0, 0.0, math.pi / 2).distance == pytest.approx(2.0)
    # Towards the barrel (0.8, -1.2), radius 0.15.
    bearing = math.atan2(-1.2, 0.8)
    hit = plan.ray(0.0, 0.0, bearing)
    assert hit.name == "barrel" and hit.distance == pytest.approx(math.hypot(0.8, 1.2) - 0.15)
    # Nearest from a point beside the south wall.
    near = plan.nearest(0.0, -1.5)
    assert near.name == "wall_south" and near.distance == pytest.approx(0.5)
    side = plan.nearest_on_side(0.0, -1.5, 0.0, -2.0, -1.2)  # facing east: the wall is right
    assert side.name == "wall_south" and side.distance == pytest.approx(0.5, abs=1e-3)
    # The body's front is 0.07 m ahead of base_link: at x = 1.93 it touches the east wall.
    assert plan.clearance(1.93, 0.0, 0.0).distance == pytest.approx(0.0, abs=1e-9)
    assert plan.clearance(1.80, 0.0, 0.0).distance == pytest.approx(0.13)
    # Turned 90 degrees, the 0.09 m half width faces the wall.
    assert plan.clearance(1.80, 0.0, math.pi / 2).distance == pytest.approx(0.11)
    # Overlapping the box counts as touching it.
    assert plan.clearance(-1.0, 0.75, 0.0).distance == 0.0


def test_a_rotated_box_in_a_frame_and_a_class_default(tmp_path):
    world = tmp_path / "world.xml"
    world.write_text(
        textwrap.dedent(
            """
            <mujoco>
              <default><default class="crate"><geom type="box" size="0.5 0.1 0.3"/></default>
              </default>
              <worldbody>
                <frame pos="1 0 0" euler="0 0 90">
                  <geom name="crate" class="crate" pos="1 0 0.3"/>
                </frame>
                <geom name="lamp" type="sphere" size="0.1" pos="0 0 2"/>
                <geom name="ramp" type="box" size="1 1 0.1" pos="0 0 0" euler="10 0 0"/>
              </worldbody>
            </mujoco>
            """
        )
    )
    plan = load_world_map(str(world))
    assert plan.names() == ["crate"]  # the lamp hangs above the robot
    assert plan.skipped == ("geom ramp (turned about x or y)",)
    # degrees (the default): the frame turns the crate by 90 degrees, to (1, 1), long along y.
    assert plan.nearest(1.0, 1.0).distance == pytest.approx(-0.1)
    assert plan.nearest(1.0, 2.0).distance == pytest.approx(0.5)
    assert plan.nearest(2.0, 1.0).distance == pytest.approx(0.9)


@pytest.mark.parametrize(
    ("world", "error"),
    [("../etc/passwd", "neither a world name"), ("nowhere", "does not exist")],
)
def test_a_world_that_cannot_be_read_is_a_clear_error(world, error):
    with pytest.raises(WorldMapError, match=error):
        load_world_map(world)
