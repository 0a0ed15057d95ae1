"""The patrol exercise's probe (``sim_patrol``) judged without a ROS graph: the routes it
draws on the office's floor plan, and its verdict on made-up ground truths: a patrol that
stops at each waypoint in order, one that skips, stops early, drives past at speed, swaps
x and y, says it finished too early, or is teleported.

test_grading runs the live gradings (the reference, the starter, each mistake, the cheat)
on one seed; here the pure logic, over many.
"""

from __future__ import annotations

import math
import random

import pytest

from app.exercises.model import load_exercises
from app.exercises.probes.sim import Sample, Touch
from app.exercises.probes.sim_patrol import (
    MIN_GAP,
    PATH_CLEARANCE,
    WAYPOINT_CLEARANCE,
    distances_from,
    draw_route,
    first_jump,
    goals_in,
    headings,
    judge,
    new_lines,
    reach_times,
    route_problems,
    speeds,
    world_grid,
)
from app.lessons.checks._sim_topics import world_map

EXERCISE = load_exercises().get("patrol")
PROBE = next(p for p in EXERCISE.probes if p.kind == "sim_patrol")
ROUTE = [(1.0, 0.2), (2.5, -0.2), (1.5, 0.3)]
TOL = 0.3
FAR = Touch(0.4, "wall", 0.0)
RATE = 50.0  # ground-truth samples a second


def drive(stops, speed=0.4, rest=1.0, start=(0.0, 0.0)):
    """Ground truth of a robot driving straight from stop to stop at ``speed``, resting
    ``rest`` s at each."""
    samples, t = [Sample(0.0, start[0], start[1], 0.0)], 0.0
    here = start
    for point in stops:
        steps = max(1, int(math.dist(here, point) / speed * RATE))
        for k in range(1, steps + 1):
            t += 1.0 / RATE
            x = here[0] + (point[0] - here[0]) * k / steps
            y = here[1] + (point[1] - here[1]) * k / steps
            samples.append(Sample(t, x, y, 0.0))
        for _ in range(int(rest * RATE)):
            t += 1.0 / RATE
            samples.append(Sample(t, point[0], point[1], 0.0))
        here = point
    return samples


def test_the_exercise_grades_three_waypoints_within_a_short_time():
    assert PROBE["topic"] == "/patrol_route"
    assert PROBE["count"] == 3 and PROBE["tolerance"] == TOL
    assert float(PROBE["within"]) <= 60.0


def test_stopping_at_each_waypoint_in_order_passes():
    samples = drive(ROUTE)
    times = reach_times(samples, ROUTE, TOL)
    assert all(t is not None for t in times) and times == sorted(times)
    verdict = judge(samples, 0.0, ROUTE, TOL, FAR, samples[-1].t)
    assert verdict.passed, verdict.text
    assert verdict.broken_at is None
    assert "all 3 waypoints reached in order" in verdict.text


def test_speed_is_measured_over_half_a_second():
    samples = drive([(2.0, 0.0)], speed=0.4, rest=1.0)
    v = speeds(samples)
    assert v[0] == 0.0
    assert v[int(1.0 * RATE)] == pytest.approx(0.4, rel=0.05)
    assert v[-1] == pytest.approx(0.0, abs=1e-9)


def test_a_waypoint_driven_past_at_speed_is_skipped():
    # The preempting script: every goal replaces the one before, the robot drives to the last
    # one, past the first without slowing down.
    samples = drive([ROUTE[2]])  # straight to the last waypoint, through (1.0, 0.2)'s reach
    problems = route_problems(samples, ROUTE, TOL)
    assert "waypoint 1 at (1.00, 0.20) was skipped" in problems[0]
    assert "passed" in problems[0] and "without stopping" in problems[0]
    assert "waypoint 2 at (2.50, -0.20) was skipped" in problems[1]
    verdict = judge(samples, 0.0, ROUTE, TOL, FAR, samples[-1].t)
    assert not verdict.passed and "was skipped" in verdict.text
    assert verdict.broken_at == pytest.approx(samples[-1].t)


def test_a_patrol_that_leaves_out_the_last_waypoint_stopped_early():
    samples = drive(ROUTE[:2])
    verdict = judge(samples, 0.0, ROUTE, TOL, FAR, samples[-1].t)
    assert not verdict.passed
    assert "the patrol stopped after waypoint 2 of 3" in verdict.text
    assert "waypoint 3 at (1.50, 0.30) was never reached" in verdict.text
    # The line came after every waypoint the robot did reach: no word about waiting.
    assert "before the robot reached" not in verdict.text


def test_swapped_coordinates_reach_nothing_and_the_goals_sent_say_why():
    swapped = [(y, x) for x, y in ROUTE]
    samples = drive(swapped)
    verdict = judge(samples, 0.0, ROUTE, TOL, FAR, samples[-1].t, sent=swapped)
    assert not verdict.passed
    assert "not one waypoint was reached" in verdict.text
    assert (
        "Nav2 was sent (0.20, 1.00), which is no waypoint of the route: waypoint 1 with x and "
        "y swapped" in verdict.text
    )
    unknown = judge(samples, 0.0, ROUTE, TOL, FAR, samples[-1].t)  # no navigator log
    assert "not one waypoint was reached" in unknown.text and "swapped" not in unknown.text


def test_a_goal_off_the_route_fails_even_when_every_waypoint_is_stopped_at():
    samples = drive(ROUTE)
    sent = [ROUTE[0], (4.0, 1.7), ROUTE[1], ROUTE[2]]
    verdict = judge(samples, 0.0, ROUTE, TOL, FAR, samples[-1].t, sent=sent)
    assert not verdict.passed
    assert "Nav2 was sent (4.00, 1.70), which is no waypoint of the route" in verdict.text
    assert "swapped" not in verdict.text
    near = [(x + 0.1, y - 0.1) for x, y in ROUTE]  # within the tolerance: the waypoints
    assert judge(samples, 0.0, ROUTE, TOL, FAR, samples[-1].t, sent=near).passed


def test_a_script_that_sends_nothing_is_told_so():
    samples = drive([])
    verdict = judge(samples, 0.0, ROUTE, TOL, FAR, None, sent=[])
    assert "not one waypoint was reached" in verdict.text
    assert "Nav2 was sent no goal at all" in verdict.text
    assert "never printed 'Patrol finished'" in verdict.text


def test_goals_are_read_from_the_navigators_log_after_where_it_stood():
    old = [f"[INFO] [1.{k}] [bt_navigator]: line {k}" for k in range(12)]
    line = (
        "[INFO] [2.0] [bt_navigator]: Begin navigating from current location (0.00, -0.00) "
        "to (-1.25, 3.40)"
    )
    later = [*old[5:], line, "[INFO] [2.1] [bt_navigator]: Begin navigating from current "
             "location (-1.25, 3.40) using 2 poses"]  # fmt: skip
    assert new_lines(old[-10:], later) == later[-2:]  # the buffer dropped its oldest lines
    assert new_lines(old[-10:], [*old, *later[-2:]]) == later[-2:]
    assert goals_in(new_lines(old[-10:], later)) == [(-1.25, 3.4)]
    assert new_lines([], old) == old
    assert new_lines(["gone"], old) == old  # the tail itself was pushed out: all is new
    assert new_lines(old[-10:], old) == []


def test_finished_printed_before_the_robot_arrived():
    samples = drive(ROUTE)
    verdict = judge(samples, 0.0, ROUTE, TOL, FAR, 0.2)
    assert not verdict.passed
    assert "printed 'Patrol finished' at 0.2 s, before the robot reached waypoint 1" in (
        verdict.text
    )
    # Nav2 says "reached" a moment before the ground truth's speed shows the stop.
    first = reach_times(samples, ROUTE, TOL)[-1]
    assert judge(samples, 0.0, ROUTE, TOL, FAR, first - 1.0).passed
    never = judge(samples, 0.0, ROUTE, TOL, FAR, None)
    assert not never.passed and "never printed 'Patrol finished'" in never.text


def test_a_teleported_robot_fails_however_well_it_stands_on_the_waypoints():
    samples, t = [Sample(0.0, 0.0, 0.0, 0.0)], 0.0
    for x, y in ROUTE:  # put on each waypoint, then standing there
        for _ in range(int(1.5 * RATE)):
            t += 1.0 / RATE
            samples.append(Sample(t, x, y, 0.0))
    assert all(time is not None for time in reach_times(samples, ROUTE, TOL))
    jump = first_jump(samples, 0.0)
    assert jump is not None and jump.distance == pytest.approx(math.dist((0, 0), ROUTE[0]))
    verdict = judge(samples, 0.0, ROUTE, TOL, FAR, samples[-1].t)
    assert not verdict.passed and "it was put there, not driven" in verdict.text
    assert verdict.broken_at == pytest.approx(1.0 / RATE)
    assert first_jump(drive(ROUTE, speed=0.5), 0.0) is None  # the wheels' top speed


def test_a_touch_fails():
    samples = drive(ROUTE)
    verdict = judge(samples, 0.0, ROUTE, TOL, Touch(0.0, "sofa", 3.5), samples[-1].t)
    assert not verdict.passed and "touched sofa at 3.5 s" in verdict.text
    assert verdict.broken_at == 3.5


def test_ending_away_from_the_last_waypoint_fails():
    samples = drive([*ROUTE, (2.5, 0.0)])
    verdict = judge(samples, 0.0, ROUTE, TOL, FAR, samples[-1].t)
    assert not verdict.passed and "did not stay at the last waypoint" in verdict.text


@pytest.mark.parametrize("seed", range(12))
def test_drawn_routes_are_clear_short_and_reachable(seed):
    grid = world_grid("office")
    plan = world_map("office")
    low, high = PROBE["leg_min"], PROBE["leg_max"]
    route = draw_route(random.Random(seed), grid, (0.0, 0.0), 3, (low, high))
    assert route == draw_route(random.Random(seed), grid, (0.0, 0.0), 3, (low, high))
    here = (0.0, 0.0)
    for point in route:
        assert plan.nearest(*point).distance >= WAYPOINT_CLEARANCE - 0.01, point
        way = distances_from(grid, here, high + 0.01)
        assert low <= way[grid.cell(*point)] <= high + 0.01, (here, point)
        here = point
    for a in [(0.0, 0.0), *route]:
        for b in route:
            assert a == b or math.dist(a, b) >= MIN_GAP
    assert len(headings((0.0, 0.0), route)) == 3
    assert PATH_CLEARANCE < WAYPOINT_CLEARANCE


def test_another_seed_draws_another_route():
    grid = world_grid("office")
    routes = {
        tuple(draw_route(random.Random(s), grid, (0.0, 0.0), 3, [1.0, 2.0])) for s in range(6)
    }
    assert len(routes) == 6
