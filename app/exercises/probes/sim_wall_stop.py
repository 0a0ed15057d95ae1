"""Probe ``sim_wall_stop``: from a random start facing a wall, the robot drives up to it and
stops in time: never closer than a bound, within reach of it before a deadline, then still.
"""

from __future__ import annotations

import math

from app.exercises.probes.base import ProbeContext, register_probe
from app.exercises.probes.sim import (
    DEFAULT_RTF,
    TOUCH,
    Recorder,
    Sample,
    World,
    at_rest,
    closest_touch,
    draw_pose,
    pose_text,
    release,
    run_until,
    simulation,
    touch_text,
)
from app.exercises.report import Result
from app.exercises.trace import Trace, thinned
from app.lessons.checks._world_map import WorldMap
from app.lessons.schema import Spec

SIDE_OFFSET = 0.1  # m: rays this far left and right of the centre see the same surface ahead
SIDE_AGREE = 0.06  # m: ... within this (the surface faces the robot, no corner in the way)
ROOM_BEHIND = 0.8  # m free behind the start: what lies behind is never mistaken for the wall


def ahead(plan: WorldMap, s: Sample) -> float:
    """What the scan's ray straight ahead would read without noise."""
    return plan.ray(s.x, s.y, s.yaw).distance


def _fits(plan: WorldMap, low: float, high: float):
    def fits(x: float, y: float, yaw: float) -> bool:
        if plan.clearance(x, y, yaw).distance < 0.2:
            return False
        centre = plan.ray(x, y, yaw).distance
        if not low <= centre <= high or plan.ray(x, y, yaw + math.pi).distance < ROOM_BEHIND:
            return False
        for side in (-SIDE_OFFSET, SIDE_OFFSET):
            sx, sy = x - side * math.sin(yaw), y + side * math.cos(yaw)
            if abs(plan.ray(sx, sy, yaw).distance - centre) > SIDE_AGREE:
                return False
        return True

    return fits


@register_probe(
    "sim_wall_stop",
    required="start",
    optional="trials closest reach within hold ahead real_time_factor",
    words="resets the world with the robot at a random start facing a wall, `trials` times; "
    "each time your node must drive up to the wall and stop: never closer than `closest` "
    "(what the scan's ray straight ahead would read), within `reach` of it before `within` "
    "simulated seconds, then still for `hold` s, and never touching anything",
    draws="a start pose per trial (x, y, yaw from the ranges, redrawn until a wall lies "
    "straight ahead at a distance in `ahead`, with room to drive and 0.8 m free behind)",
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
                return Result("stop before the wall", False, "; ".join(lines), tuple(traces))
    return Result("stop before the wall", True, "; ".join(lines), tuple(traces))


def _trace(
    trial: int, closest: float, points: list[tuple[float, float]], broken: tuple[float, str]
) -> Trace:
    at, why = broken
    return Trace.of(
        f"distance to the wall ahead, trial {trial}",
        "m",
        thinned(points),
        low=closest,
        broken_at=at if why else None,
        broken_why=why,
    )


def _trial(
    ctx: ProbeContext, p: Spec, world: World, recorder: Recorder, trial: int
) -> tuple[bool, str, Trace | None]:
    closest, reach = float(p.get("closest", 0.35)), float(p.get("reach", 0.65))
    within, hold = float(p.get("within", 25.0)), float(p.get("hold", 3.0))
    low, high = p.get("ahead", [1.2, 3.0])
    plan = world.plan
    start = draw_pose(ctx, p["start"], _fits(plan, float(low), float(high)))
    wall = plan.ray(*start)
    t0 = release(ctx, world, recorder, start)
    reached: list[float] = []  # the time the robot first came within reach
    seen = [0]  # samples looked at so far

    def done(samples: list[Sample]) -> bool:
        for s in samples[seen[0] :]:
            if plan.clearance(s.x, s.y, s.yaw).distance <= TOUCH or ahead(plan, s) < closest:
                return True  # failed already: no need to watch on
            if not reached and ahead(plan, s) <= reach:
                reached.append(s.t - t0)
        seen[0] = len(samples)
        settled = at_rest(samples, hold) and not recorder.asked_to_move()
        if not reached:
            return settled  # it stopped short: waiting on would change nothing
        return samples[-1].t - t0 >= reached[0] + hold and settled

    samples, stalled = run_until(ctx, recorder, t0, start, within + hold, world.rtf, done)
    began = f"start {pose_text(start)} with {wall.name} {wall.distance:.2f} m ahead"
    if stalled:
        return False, f"{began}; {stalled}", None
    if not samples:
        return False, f"{began}; no ground truth arrived during the trial", None
    distances = [ahead(plan, s) for s in samples]
    points = [(s.t - t0, d) for s, d in zip(samples, distances, strict=True)]
    nearest = min(distances)
    touch = closest_touch(plan, samples, t0)
    last, final = samples[-1], distances[-1]
    problems = []
    broken = (0.0, "")  # when and why the plot marks the trial as lost
    if touch.distance <= TOUCH:
        problems.append(touch_text(touch))
        broken = (touch.at, f"touched {touch.name}")
    if nearest < closest:
        at = samples[distances.index(nearest)].t - t0
        first = next(t for t, d in points if d < closest)
        broken = broken if broken[1] else (first, f"closer than {closest:g} m")
        problems.append(
            f"it came to {nearest:.3f} m of the wall ahead at {at:.1f} s: closer than "
            f"the bound {closest:g} m"
        )
    if not reached:
        moved = math.hypot(last.x - start[0], last.y - start[1])
        why = (
            " (does your node keep publishing a forward /cmd_vel? The base stops 0.5 s after "
            "the last one)"
            if moved < 0.1
            else ""
        )
        if last.t - t0 >= within:
            how = f" in {within:g} s: it moved {moved:.2f} m and ended {final:.2f} m from it"
        else:
            how = f": it came to rest {final:.2f} m from it after moving {moved:.2f} m"
        problems.append(f"it did not come within {reach:g} m of the wall{how}{why}")
        broken = broken if broken[1] else (last.t - t0, f"never within {reach:g} m")
    elif not problems and not at_rest(samples, hold):
        problems.append(
            f"it came within {reach:g} m at {reached[0]:.1f} s but did not stand still for "
            f"{hold:g} s (now {final:.2f} m from the wall)"
        )
        broken = (last.t - t0, "still moving")
    elif not problems and not closest <= final <= reach:
        problems.append(f"it stopped {final:.2f} m from the wall, outside {closest:g}-{reach:g} m")
        broken = (last.t - t0, f"stopped {final:.2f} m away")
    trace = _trace(trial, closest, points, broken)
    if problems:
        return False, f"{began}; " + "; ".join(problems), trace
    speed = (wall.distance - reach) / reached[0] if reached[0] > 0 else 0.0
    return (
        True,
        f"{began}; within {reach:g} m after {reached[0]:.1f} s (about {speed:.2f} m/s), "
        f"stopped {final:.2f} m from it (closest {nearest:.2f} m, bound {closest:g} m), "
        f"still for {hold:g} s; {touch_text(touch)}",
        trace,
    )
