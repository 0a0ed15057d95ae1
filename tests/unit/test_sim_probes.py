"""The simulation probes' drawing and judging, without ROS: starts and goals drawn from a
seed fit the room (and replay with the same seed), and the figures a verdict rests on
(rest, distance driven, touching) are computed from poses as the ground truth gives them.
"""

from __future__ import annotations

import math
import random
from types import SimpleNamespace

import pytest

from app.exercises.probes.sim import Sample, at_rest, closest_touch, draw_pose, path_length
from app.exercises.probes.sim_go_to_goal import draw_trial, in_world
from app.exercises.probes.sim_wall_follow import _fits as follow_fits
from app.exercises.probes.sim_wall_follow import side_distance
from app.exercises.probes.sim_wall_stop import _fits as stop_fits
from app.exercises.probes.sim_wall_stop import ahead
from app.lessons.checks._world_map import load_world_map
from app.lessons.schema import Spec

PLAN = load_world_map("room")
ROOM = {"x": [-1.7, 1.7], "y": [-1.7, 1.7], "yaw": [-3.14, 3.14]}


def ctx(seed: int):
    return SimpleNamespace(rng=random.Random(seed))  # all draw_pose uses of a ProbeContext


def test_a_seed_replays_the_start_and_another_seed_changes_it():
    fits = stop_fits(PLAN, 1.2, 3.2)
    assert draw_pose(ctx(7), ROOM, fits) == draw_pose(ctx(7), ROOM, fits)
    assert draw_pose(ctx(7), ROOM, fits) != draw_pose(ctx(8), ROOM, fits)


@pytest.mark.parametrize("seed", range(8))
def test_a_wall_stop_start_faces_a_wall_with_room_to_drive(seed):
    x, y, yaw = draw_pose(ctx(seed), ROOM, stop_fits(PLAN, 1.2, 3.2))
    assert 1.2 <= ahead(PLAN, Sample(0.0, x, y, yaw)) <= 3.2
    assert PLAN.clearance(x, y, yaw).distance >= 0.2
    assert PLAN.ray(x, y, yaw + math.pi).distance >= 0.8


@pytest.mark.parametrize("seed", range(8))
def test_a_wall_follow_start_has_a_long_wall_abeam_on_the_right(seed):
    x, y, yaw = draw_pose(ctx(seed), ROOM, follow_fits(PLAN, -1.0, 0.3, 0.6))
    beside = side_distance(PLAN, Sample(0.0, x, y, yaw), -1.0)
    assert 0.3 <= beside.distance <= 0.6
    assert abs(beside.bearing + math.pi / 2) <= 0.35
    assert beside.name.startswith("wall_")  # not the box, the barrel or the table
    assert PLAN.ray(x, y, yaw).distance >= 1.0


@pytest.mark.parametrize("seed", range(8))
def test_a_goal_is_in_range_and_its_straight_way_is_free(seed):
    probe = Spec(
        "sim_go_to_goal",
        {
            "start": {"x": [-1.5, 1.5], "y": [-1.5, 1.5], "yaw": [-3.14, 3.14]},
            "goal": {"distance": [0.8, 1.8], "bearing": [-3.14, 3.14], "yaw": [-3.14, 3.14]},
        },
    )
    start, goal, target = draw_trial(ctx(seed), probe, PLAN)  # type: ignore[arg-type]
    assert 0.8 - 1e-3 <= math.hypot(goal[0], goal[1]) <= 1.8 + 1e-3
    assert target == pytest.approx(in_world(start, goal))
    for k in range(21):
        px = start[0] + (target[0] - start[0]) * k / 20
        py = start[1] + (target[1] - start[1]) * k / 20
        assert PLAN.nearest(px, py).distance >= 0.2


def test_a_goal_in_the_odom_frame_lands_where_the_start_points():
    # Start at (1, 1) facing +y: "1 m ahead, facing left" is (1, 2) facing -x in the world.
    x, y, yaw = in_world((1.0, 1.0, math.pi / 2), (1.0, 0.0, math.pi / 2))
    assert (x, y) == pytest.approx((1.0, 2.0)) and abs(abs(yaw) - math.pi) < 1e-9


def _line(v: float, seconds: float, hz: float = 30.0) -> list[Sample]:
    return [Sample(i / hz, v * i / hz, 0.0, 0.0) for i in range(int(seconds * hz) + 1)]


def test_rest_distance_and_touching_from_ground_truth_poses():
    driving = _line(0.2, 3.0)
    assert path_length(driving) == pytest.approx(0.6)
    assert not at_rest(driving, 2.0)
    creeping = _line(0.02, 3.0)  # a slow final approach still moves
    assert not at_rest(creeping, 2.0)
    stopped = driving + [Sample(3.0 + i / 30, 0.6, 0.0, 0.0) for i in range(1, 91)]
    assert at_rest(stopped, 2.0) and not at_rest(stopped[:95], 2.0)
    # Driving east from the middle of the room: the body's front (0.07 m) meets the east
    # wall's inner face (x = 2) when base_link is at x = 1.93.
    into_wall = [Sample(i * 0.1, 1.5 + i * 0.05, 0.0, 0.0) for i in range(10)]
    touch = closest_touch(PLAN, into_wall, 0.0)
    assert touch.name == "wall_east" and touch.distance <= 0.0 and touch.at == pytest.approx(0.9)
