"""Probe ``sim_go_to_goal``: from a random start, the robot drives to a random goal pose given
as parameters in its odometry frame, and stops there: final position and heading errors
below bounds, measured on the ground truth.
"""

from __future__ import annotations

import math

from app.exercises.probes.base import ProbeContext, draw, register_probe
from app.exercises.probes.sim import (
    DEFAULT_RTF,
    TOUCH,
    Recorder,
    Sample,
    World,
    at_rest,
    closest_touch,
    path_length,
    pose_text,
    release,
    run_until,
    simulation,
    touch_text,
)
from app.exercises.report import Result
from app.exercises.trace import Trace, thinned
from app.lessons.checks._sim_topics import wrap
from app.lessons.checks._world_map import WorldMap
from app.lessons.schema import Spec

ROOM_TO_TURN = 0.22  # m from the base's centre to anything: it can turn on the spot there
STEP = 0.05  # m between the points of the straight way that must be free
PARAMETERS = ("goal_x", "goal_y", "goal_yaw")
GOAL_FIELDS = ("distance", "bearing", "yaw")
IDLE = 10.0  # s standing still: the trial ends


def in_world(start: tuple[float, float, float], goal: tuple[float, float, float]):
    """A pose given in the start's frame (the odometry frame after a reset), in the world."""
    sx, sy, syaw = start
    gx, gy, gyaw = goal
    c, s = math.cos(syaw), math.sin(syaw)
    return sx + c * gx - s * gy, sy + s * gx + c * gy, wrap(syaw + gyaw)


def _way_is_free(plan: WorldMap, a: tuple[float, float], b: tuple[float, float]) -> bool:
    steps = max(1, int(math.dist(a, b) / STEP))
    return all(
        plan.nearest(a[0] + (b[0] - a[0]) * k / steps, a[1] + (b[1] - a[1]) * k / steps).distance
        >= ROOM_TO_TURN
        for k in range(steps + 1)
    )


def draw_trial(ctx: ProbeContext, p: Spec, plan: WorldMap, tries: int = 20000):
    """A start (world) and a goal (start's frame) with a free straight way between them."""
    for _ in range(tries):
        start = tuple(float(draw(ctx.rng, p["start"][k])) for k in ("x", "y", "yaw"))
        distance, bearing, yaw = (float(draw(ctx.rng, p["goal"][k])) for k in GOAL_FIELDS)
        goal = (round(distance * math.cos(bearing), 3), round(distance * math.sin(bearing), 3), yaw)
        target = in_world(start, goal)  # type: ignore[arg-type]
        if plan.clearance(*start).distance >= 0.1 and _way_is_free(
            plan, (start[0], start[1]), (target[0], target[1])
        ):
            return start, goal, target
    raise ValueError(f"no start and goal drawn from {p['start']}, {p['goal']} fit the world")


@register_probe(
    "sim_go_to_goal",
    required="start goal",
    optional="trials position_tolerance heading_tolerance within hold real_time_factor",
    words="resets the world with the robot at a random start and sets a random goal on your "
    "node (parameters goal_x, goal_y, goal_yaw, in the odom frame: the start is its origin), "
    "`trials` times; each time the robot must come to rest within `within` simulated seconds "
    "with its real position and heading within the tolerances of the goal, never touching "
    "anything",
    draws="a start pose and a goal per trial (distance, bearing and heading from the start, "
    "from the ranges; redrawn until the straight way between them is free)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    trials = int(p.get("trials", 2))
    lines, traces = [], []
    with simulation(ctx, float(p.get("real_time_factor", DEFAULT_RTF))) as (world, recorder):
        for trial in range(trials):
            passed, text, trace = _trial(ctx, p, world, recorder, trial + 1)
            lines.append(f"trial {trial + 1}: {text}")
            traces.extend([trace] if trace else [])
            if not passed:
                return Result("drive to the goal", False, "; ".join(lines), tuple(traces))
    return Result("drive to the goal", True, "; ".join(lines), tuple(traces))


def _trial(
    ctx: ProbeContext, p: Spec, world: World, recorder: Recorder, trial: int
) -> tuple[bool, str, Trace | None]:
    position_tolerance = float(p.get("position_tolerance", 0.15))
    heading_tolerance = float(p.get("heading_tolerance", 0.25))
    within, hold = float(p.get("within", 40.0)), float(p.get("hold", 2.0))
    plan = world.plan
    start, goal, target = draw_trial(ctx, p, plan)
    told = dict(zip(PARAMETERS, goal, strict=True))
    t0 = release(ctx, world, recorder, start, told)
    seen = [0]

    def done(samples: list[Sample]) -> bool:
        if any(plan.clearance(s.x, s.y, s.yaw).distance <= TOUCH for s in samples[seen[0] :]):
            return True  # failed already: no need to watch on
        seen[0] = len(samples)
        if at_rest(samples, IDLE):
            return True  # it does not move (any more): waiting on would change nothing
        settled = at_rest(samples, hold) and not recorder.asked_to_move()
        return path_length(samples) > 0.05 and settled

    samples, stalled = run_until(ctx, recorder, t0, start, within, world.rtf, done)
    began = (
        f"start {pose_text(start)}, goal {pose_text(goal)} in the odom frame "
        f"= {pose_text(target)} in the world"
    )
    if stalled:
        return False, f"{began}; {stalled}", None
    if not samples:
        return False, f"{began}; no ground truth arrived during the trial", None
    last = samples[-1]
    off = math.hypot(last.x - target[0], last.y - target[1])
    turned = abs(wrap(last.yaw - target[2]))
    spent = last.t - t0
    figures = (
        f"after {spent:.1f} s the robot is at {pose_text((last.x, last.y, last.yaw))}: "
        f"{off:.3f} m and {turned:.3f} rad from the goal"
    )
    odom = recorder.odom_since(t0)
    if odom:
        belief = odom[-1]
        figures += (
            f" (its odometry says {math.hypot(belief.x - goal[0], belief.y - goal[1]):.3f} m "
            f"and {abs(wrap(belief.yaw - goal[2])):.3f} rad)"
        )
    touch = closest_touch(plan, samples, t0)
    problems = []
    touched = touch.distance <= TOUCH
    if touched:
        problems.append(touch_text(touch))
    if off > position_tolerance:
        problems.append(f"position error {off:.3f} m is above {position_tolerance:g} m")
    if turned > heading_tolerance:
        problems.append(f"heading error {turned:.3f} rad is above {heading_tolerance:g} rad")
    if not touched and not at_rest(samples, hold):
        problems.append(f"it did not come to rest within {within:g} s")
    if touched:
        broken = (touch.at, f"touched {touch.name}")
    elif problems:  # judged where it ended: the last moment is where it was lost
        broken = (spent, f"ended {off:.2f} m, {turned:.2f} rad off")
    else:
        broken = (0.0, "")
    trace = Trace.of(
        f"distance to the goal, trial {trial} (judged where it ends)",
        "m",
        thinned([(s.t - t0, math.hypot(s.x - target[0], s.y - target[1])) for s in samples]),
        high=position_tolerance,
        broken_at=broken[0] if broken[1] else None,
        broken_why=broken[1],
    )
    if problems:
        return False, f"{began}; {figures}; " + "; ".join(problems), trace
    return True, f"{began}; {figures}; {touch_text(touch)}", trace
