"""The turtlesim world without ROS: motion, timeout, walls, pens, spawn, goals."""

from __future__ import annotations

import math

import pytest

from nodes.common.turtlesim_world import (
    CENTRE,
    DEFAULT_PEN,
    UNPAINTED,
    UPDATE_PERIOD,
    WORLD_SIZE,
    BadRequest,
    GoalOutcome,
    TurtleWorld,
    normalize_angle,
)


def run(world: TurtleWorld, seconds: float, start: float = 0.0) -> tuple[float, list]:
    """Step the world for ``seconds`` of simulated time; returns (clock, last reports)."""
    now, reports = start, []
    for _ in range(round(seconds / UPDATE_PERIOD)):
        now += UPDATE_PERIOD
        reports = world.step(now)
    return now, reports


@pytest.fixture
def world() -> TurtleWorld:
    w = TurtleWorld(seed=1)
    w.reset()
    return w


def test_the_world_is_upstreams_window_and_turtle1_starts_at_its_centre(world):
    assert WORLD_SIZE == pytest.approx(11.088889, abs=1e-6)
    assert CENTRE == pytest.approx(5.544445, abs=1e-6)
    (report,) = world.step(UPDATE_PERIOD)
    assert (report.name, report.x, report.y, report.theta) == ("turtle1", CENTRE, CENTRE, 0.0)
    assert report.color == UNPAINTED  # nothing drawn yet


def test_normalize_angle_is_half_open_at_pi():
    assert normalize_angle(math.pi) == pytest.approx(-math.pi)
    assert normalize_angle(-math.pi) == pytest.approx(-math.pi)
    assert normalize_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)


def test_velocity_holds_for_one_second_then_stops(world):
    world.command_velocity("turtle1", 2.0, 0.0, 0.0, now=0.0)
    now, (moving,) = run(world, 0.5)
    assert moving.linear_velocity == 2.0
    now, (stopped,) = run(world, 1.0, now)
    assert stopped.linear_velocity == 0.0
    # Steps at t <= 1.0 s move: 62 or 63 steps of 16 ms at 2 m/s.
    assert stopped.x - CENTRE == pytest.approx(2.0, abs=2 * 2 * UPDATE_PERIOD)


def test_holonomic_moves_sideways_only_when_enabled(world):
    world.command_velocity("turtle1", 0.0, 1.0, 0.0, now=0.0, holonomic=False)
    _, (report,) = run(world, 0.5)
    assert report.y == CENTRE
    world.command_velocity("turtle1", 0.0, 1.0, 0.0, now=0.5, holonomic=True)
    _, (report,) = run(world, 0.5, 0.5)
    assert report.y - CENTRE == pytest.approx(0.5, abs=0.02)
    assert report.x == pytest.approx(CENTRE)


def test_the_wall_clamps_and_reports_window_coordinates(world):
    world.teleport_absolute("turtle1", 11.0, 2.0, 0.0)
    world.command_velocity("turtle1", 1.0, 0.0, 0.0, now=0.0)
    _, (report,) = run(world, 0.5)
    assert report.x == WORLD_SIZE and report.y == pytest.approx(2.0)
    assert report.wall_hit is not None
    assert report.wall_hit.x == pytest.approx(WORLD_SIZE + UPDATE_PERIOD)
    assert report.wall_hit.y == pytest.approx(WORLD_SIZE - 2.0)  # y counted from the top
    assert report.wall_hit.message() == (
        f"Oh no! I hit the wall! (Clamping from [x={report.wall_hit.x:f}, y={WORLD_SIZE - 2.0:f}])"
    )


def test_teleports_apply_in_order_and_draw_with_the_pen(world):
    world.teleport_absolute("turtle1", 1.0, 1.0, 0.0)
    world.teleport_relative("turtle1", 2.0, math.pi / 2)
    (report,) = world.step(UPDATE_PERIOD)
    assert (report.x, report.y) == pytest.approx((1.0, 3.0))
    assert report.theta == pytest.approx(math.pi / 2)
    assert world.segment_count == 2
    assert report.color == DEFAULT_PEN
    world.teleport_absolute("turtle1", 3.0, 50.0, 0.0)  # above the top: clamped to the wall
    (report,) = world.step(2 * UPDATE_PERIOD)
    assert report.y == WORLD_SIZE and report.wall_hit is None


def test_pen_colour_width_and_off(world):
    world.set_pen("turtle1", 10, 20, 30, 0, 0)
    assert world.turtles["turtle1"].pen_width == 1  # width 0 means a new 1-pixel pen
    world.command_velocity("turtle1", 1.0, 0.0, 0.0, now=0.0)
    _, (report,) = run(world, 0.2)
    assert report.color == (10, 20, 30)
    world.set_pen("turtle1", 0, 0, 0, 0, 1)
    drawn = world.segment_count
    world.teleport_absolute("turtle1", 9.0, 9.0, 0.0)
    (report,) = world.step(0.3)
    assert world.segment_count == drawn and report.color == UNPAINTED
    assert world.turtles["turtle1"].pen_color == (10, 20, 30)  # off keeps the colour


def test_clear_wipes_trails_but_keeps_turtles(world):
    world.command_velocity("turtle1", 1.0, 0.0, 0.0, now=0.0)
    run(world, 0.3)
    cleared_before = world.clear_count
    world.clear()
    assert world.segments_since(0) == [] and world.clear_count == cleared_before + 1
    (report,) = world.step(0.4)
    assert report.color == DEFAULT_PEN  # still moving: it draws again at once
    assert "turtle1" in world.turtles


def test_spawn_names_duplicates_kill_and_reset(world):
    assert world.spawn("", 1.0, 1.0, 0.0) == "turtle2"
    assert world.spawn("turtle2", 1.0, 1.0, 0.0) is None
    assert world.spawn("raphael", 1.0, 1.0, 0.0) == "raphael"
    assert world.spawn("", 1.0, 1.0, 0.0) == "turtle3"
    assert world.kill("nobody") is None
    assert world.kill("turtle2") is not None
    assert world.spawn("", 1.0, 1.0, 0.0) == "turtle4"  # the counter does not reuse names
    world.reset()
    assert list(world.turtles) == ["turtle1"]
    assert world.spawn("", 1.0, 1.0, 0.0) == "turtle2"


def test_rotation_turns_at_one_radian_per_second_with_feedback_every_step(world):
    world.start_rotation("turtle1", "goal", math.pi / 2)
    now, updates = 0.0, []
    while True:
        now += UPDATE_PERIOD
        (report,) = world.step(now)
        updates.append(report.rotation)
        if report.rotation.outcome is not None:
            break
        assert now < 3.0
    assert updates[-1].outcome is GoalOutcome.SUCCEEDED
    assert len(updates) == pytest.approx((math.pi / 2) / UPDATE_PERIOD, abs=2)
    assert abs(report.theta - math.pi / 2) < 0.02
    assert updates[-1].delta == pytest.approx(-report.theta)
    assert updates[0].remaining == pytest.approx(math.pi / 2)
    assert report.angular_velocity == 0.0


def test_rotation_is_replaced_cancelled_or_aborted_by_cmd_vel(world):
    assert world.start_rotation("turtle1", "a", 3.0) is None
    world.step(UPDATE_PERIOD)
    assert world.start_rotation("turtle1", "b", -1.0).goal_id == "a"
    world.step(2 * UPDATE_PERIOD)
    aborted = world.command_velocity("turtle1", 0.0, 0.0, 0.5, now=0.04)
    assert aborted is not None and aborted.goal_id == "b"
    world.start_rotation("turtle1", "c", 3.0)
    world.cancel_rotation("turtle1", "other")  # not this goal: ignored
    world.cancel_rotation("turtle1", "c")
    (report,) = world.step(0.06)
    assert report.rotation.outcome is GoalOutcome.CANCELED and report.angular_velocity == 0.0
    assert world.turtles["turtle1"].rotation is None


def test_a_running_rotation_keeps_the_command_timeout_away(world):
    world.start_rotation("turtle1", "g", math.pi - 0.05)
    _, (report,) = run(world, 2.5)  # longer than the 1 s timeout: still turning
    assert report.rotation is not None and report.rotation.outcome is None
    assert report.angular_velocity == 1.0


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_numbers_that_are_not_finite_are_refused_and_change_nothing(world, bad):
    with pytest.raises(BadRequest, match="finite"):
        world.command_velocity("turtle1", bad, 0.0, 0.0, now=0.0)
    with pytest.raises(BadRequest):
        world.teleport_absolute("turtle1", 1.0, bad, 0.0)
    with pytest.raises(BadRequest):
        world.teleport_relative("turtle1", bad, 0.0)
    with pytest.raises(BadRequest):
        world.spawn("", bad, 1.0, 0.0)
    (report,) = world.step(UPDATE_PERIOD)
    assert (report.x, report.y, report.linear_velocity) == (CENTRE, CENTRE, 0.0)


def test_huge_finite_numbers_end_at_the_wall(world):
    world.teleport_absolute("turtle1", 3e38, -3e38, 3e38)
    _, (report,) = run(world, 2 * UPDATE_PERIOD)
    assert (report.x, report.y) == (WORLD_SIZE, 0.0) and math.isfinite(report.theta)


def test_viewers_get_new_segments_since_their_last_count(world):
    world.command_velocity("turtle1", 1.0, 0.0, 0.0, now=0.0)
    run(world, 0.16)
    seen = world.segment_count
    assert seen == 10
    run(world, 0.08, 0.16)
    new = world.segments_since(seen)
    assert len(new) == 5
    assert new[0].x0 == pytest.approx(world.segments_since(seen - 1)[0].x1)
