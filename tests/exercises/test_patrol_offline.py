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
from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage

from app.exercises.probes.sim import (
    SILENT_DRIVE,
    Command,
    Sample,
    SilentDrive,
    Touch,
    silent_drives,
)
from app.exercises.probes.sim_patrol import (
    MIN_GAP,
    PATH_CLEARANCE,
    WAYPOINT_CLEARANCE,
    AmclWatch,
    distances_from,
    draw_route,
    first_jump,
    goals_in,
    headings,
    judge,
    nav2_failures,
    new_lines,
    reach_times,
    route_problems,
    speeds,
    spoiled_by,
    world_grid,
)
from app.lessons.checks._sim_topics import world_map
from tests.course_data import shared_exercises

EXERCISE = shared_exercises().get("patrol")
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


def test_a_failed_trial_quotes_what_nav2s_navigator_said():
    lines = [
        "[INFO] [2.0] [bt_navigator]: Goal succeeded",
        "[ERROR] [3.0] [bt_navigator]: Goal failed: No valid path found (error code 206)",
        "[ERROR] [4.0] [bt_navigator]: Goal failed: Start occupied (error code 207)",
    ]
    said = nav2_failures(lines)
    assert (
        said == "; Nav2's navigator said: Goal failed: Start occupied (error code 207) (and 1 more)"
    )
    assert nav2_failures(lines[:2]).endswith("No valid path found (error code 206)")
    assert nav2_failures(lines[:1]) == ""


def test_amcl_is_read_where_its_map_to_odom_puts_the_robot():
    watch = AmclWatch()
    assert watch.robot() is None  # nothing heard yet
    quarter = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))
    watch.on_tf(_tf(("map", "odom", 1.0, 2.0, quarter), ("odom", "base_link", 1.0, 0.0, None)))
    x, y = watch.robot()
    assert math.isclose(x, 1.0, abs_tol=1e-9) and math.isclose(y, 3.0, abs_tol=1e-9)


def _tf(*parts):
    msg = TFMessage()
    for parent, child, x, y, q in parts:
        t = TransformStamped()
        t.header.frame_id, t.child_frame_id = parent, child
        t.transform.translation.x, t.transform.translation.y = x, y
        if q is not None:
            r = t.transform.rotation
            r.x, r.y, r.z, r.w = q
        msg.transforms.append(t)
    return msg


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


def _commands(*times_and_motion):
    return [Command(sent, moving) for sent, moving in times_and_motion]


def test_a_moving_command_followed_by_silence_is_a_silent_drive_on_the_worlds_clock():
    # The world sent sample k at wall time 100 + k/50 with simulation time 10 + k/50, but
    # from wall 101 on it ran at half speed (a busy machine): wall 103 is simulated 12.0.
    clock = [(100.0 + k / 50, 10.0 + k / 50) for k in range(51)]
    clock += [(101.0 + k / 50, 11.0 + k / 100) for k in range(1, 101)]
    every = [(100.0 + k / 20, True) for k in range(21)]  # 20 Hz until wall 101
    commands = _commands(*every, (101.9, True), (102.0, False), (102.9, False))
    drives = silent_drives(commands, clock, t0=10.0)
    # 101.0 -> 101.9 wall is 11.0 -> 11.45 simulated: one silent drive; the gap after the
    # zero command (the robot was told to stop) is none.
    assert drives == [SilentDrive(pytest.approx(1.0), pytest.approx(0.45, abs=0.011))]
    assert silent_drives(commands, clock, t0=11.5) == []  # before the trial: not its own
    assert silent_drives(commands[:21], clock, t0=10.0) == []  # 20 Hz: never silent
    slow = _commands((100.0, True), (100.0 + SILENT_DRIVE * 0.9, True))
    assert silent_drives(slow, clock, t0=9.0) == []  # a late tick is no silent drive
    assert silent_drives(commands, [], t0=0.0) == []


def test_a_route_lost_to_a_starved_controller_proves_nothing_and_a_script_mistake_does():
    samples = drive([ROUTE[2]])  # waypoints 1 and 2 driven through
    skipped = judge(samples, 0.0, ROUTE, TOL, FAR, samples[-1].t)
    starved = [SilentDrive(2.0, 0.8)]
    why = spoiled_by(starved, skipped, finished=True)
    assert "sent no command for 0.8 s at 2.0 s" in why and "too busy" in why
    assert spoiled_by([], skipped, finished=True) == ""  # the script's own doing
    # Still driving its first route when the trial ended: a second would meet it.
    assert spoiled_by(starved, skipped, finished=False) == ""
    late = [SilentDrive(samples[-1].t + 1.0, 0.8)]  # after the trial was lost
    assert spoiled_by(late, skipped, finished=True) == ""
    passed = judge(drive(ROUTE), 0.0, ROUTE, TOL, FAR, drive(ROUTE)[-1].t)
    assert passed.passed and spoiled_by(starved, passed, finished=True) == ""
    touched = judge(samples, 0.0, ROUTE, TOL, Touch(0.0, "sofa", 3.5), samples[-1].t)
    assert spoiled_by(starved, touched, finished=True)  # drove into it on an old command
    assert spoiled_by([SilentDrive(4.0, 0.8)], touched, finished=True) == ""  # touched first


def test_a_goal_off_the_route_or_a_jump_is_never_excused_by_a_busy_machine():
    samples = drive(ROUTE)
    stray = judge(samples, 0.0, ROUTE, TOL, FAR, samples[-1].t, sent=[(5.0, 5.0), *ROUTE])
    assert not stray.passed and spoiled_by([SilentDrive(1.0, 1.0)], stray, True) == ""
    jumped = [Sample(0.0, 0.0, 0.0, 0.0), *(Sample(t, *ROUTE[0], 0.0) for t in (0.02, 5.0))]
    verdict = judge(jumped, 0.0, ROUTE, TOL, FAR, 5.0)
    assert "not driven" in verdict.text and spoiled_by([SilentDrive(0.0, 1.0)], verdict, True) == ""
