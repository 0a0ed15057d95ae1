"""Probe ``sim_wall_follow``: from a random start beside a wall, the robot follows the wall on
one side for a while: the distance to it stays in a band, it covers ground, it never touches.
"""

from __future__ import annotations

import dataclasses
import math

from app.exercises.probes.base import ProbeContext, register_probe
from app.exercises.probes.sim import (
    DEFAULT_RTF,
    TOUCH,
    Sample,
    at_rest,
    closest_touch,
    draw_pose,
    path_length,
    pose_text,
    release,
    run_until,
    simulation,
    touch_text,
)
from app.exercises.report import Result
from app.exercises.trace import Trace, thinned
from app.lessons.checks._world_map import Box, Nearest, WorldMap
from app.lessons.schema import Spec

# The side a wall is "on": the nearest obstacle seen at these bearings (rad, robot frame).
SECTOR = (0.7, 2.4)
SAMPLE_EVERY = 0.1  # s of simulation between two judged samples (the scan's own rate)
STUCK = 10.0  # s standing still after the settling time: the trial ends there
WALL_LENGTH = 1.5  # m: a start is beside a wall, not a box or a barrel (they are circled)


def side_distance(plan: WorldMap, s: Sample, sign: float) -> Nearest:
    """The nearest obstacle on one side (sign -1: right, +1: left), as a scan would see it."""
    low, high = sorted((sign * SECTOR[0], sign * SECTOR[1]))
    return plan.nearest_on_side(s.x, s.y, s.yaw, low, high, step=0.02)


def _fits(plan: WorldMap, sign: float, low: float, high: float):
    def fits(x: float, y: float, yaw: float) -> bool:
        if plan.clearance(x, y, yaw).distance < 0.15 or plan.ray(x, y, yaw).distance < 1.0:
            return False
        near = side_distance(plan, Sample(0.0, x, y, yaw), sign)
        # Beside the wall, roughly parallel to it: its nearest point is abeam (+-20 deg).
        if not low <= near.distance <= high or abs(near.bearing - sign * math.pi / 2) > 0.35:
            return False
        beside = next(o for o in plan.obstacles if o.name == near.name)
        return isinstance(beside, Box) and 2.0 * max(beside.half_x, beside.half_y) >= WALL_LENGTH

    return fits


def _thinned(samples: list[Sample]) -> list[Sample]:
    kept: list[Sample] = []
    for s in samples:
        if not kept or s.t - kept[-1].t >= SAMPLE_EVERY - 1e-6:
            kept.append(s)
    return kept


@register_probe(
    "sim_wall_follow",
    required="start",
    optional="side band_min band_max duration settle in_band min_travel wall_at real_time_factor",
    words="resets the world with the robot at a random start beside a wall (on `side`) and "
    "lets your node drive for `duration` simulated seconds: after `settle` s, the nearest "
    "obstacle on that side must stay between `band_min` and `band_max` m away for at least "
    "`in_band` of the time, the robot must drive at least `min_travel` m, never stand still "
    f"for {STUCK:g} s and never touch anything",
    draws="a start pose (x, y, yaw from the ranges, redrawn until a wall (a box 1.5 m long or "
    "more) runs along the robot's side at a distance in `wall_at`, with 1 m free ahead)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    side = str(p.get("side", "right"))
    if side not in ("right", "left"):
        raise ValueError(f"side must be 'right' or 'left', got {side!r}")
    sign = -1.0 if side == "right" else 1.0
    low, high = float(p.get("band_min", 0.2)), float(p.get("band_max", 0.7))
    duration, settle = float(p.get("duration", 40.0)), float(p.get("settle", 5.0))
    in_band, min_travel = float(p.get("in_band", 0.85)), float(p.get("min_travel", 4.0))
    wall_low, wall_high = (float(v) for v in p.get("wall_at", [0.3, 0.6]))
    name = f"follow the wall on the {side}"
    with simulation(ctx, float(p.get("real_time_factor", DEFAULT_RTF))) as (world, recorder):
        plan = world.plan
        start = draw_pose(ctx, p["start"], _fits(plan, sign, wall_low, wall_high))
        beside = side_distance(plan, Sample(0.0, *start), sign)
        t0 = release(ctx, world, recorder, start)
        seen = [0]

        def done(samples: list[Sample]) -> bool:
            hit = any(plan.clearance(s.x, s.y, s.yaw).distance <= TOUCH for s in samples[seen[0] :])
            seen[0] = len(samples)
            stuck = samples[-1].t - t0 >= settle + STUCK and at_rest(samples, STUCK)
            return hit or stuck  # failed already: no need to watch on

        samples, stalled = run_until(ctx, recorder, t0, start, duration, world.rtf, done)
    began = f"start {pose_text(start)} with {beside.name} {beside.distance:.2f} m to the {side}"
    if stalled:
        return Result(name, False, f"{began}; {stalled}")
    if not samples:
        return Result(name, False, f"{began}; no ground truth arrived during the trial")
    touch = closest_touch(plan, samples, t0)
    travel = path_length(samples)
    every = [(s.t - t0, side_distance(plan, s, sign).distance) for s in _thinned(samples)]
    distances = [d for t, d in every if t >= settle]
    inside = sum(low <= d <= high for d in distances)
    share = inside / len(distances) if distances else 0.0
    spent = samples[-1].t - t0
    figures = f"drove {travel:.2f} m in {spent:.1f} s"
    if distances:
        mean = sum(distances) / len(distances)
        figures += (
            f"; after the first {settle:g} s the {side} wall was {min(distances):.2f}-"
            f"{max(distances):.2f} m away (mean {mean:.2f} m), within {low:g}-{high:g} m "
            f"{share:.0%} of the time"
        )
    problems = []
    broken = (0.0, "")  # when and why the plot marks the run as lost
    if touch.distance <= TOUCH:
        problems.append(touch_text(touch))
        broken = (touch.at, f"touched {touch.name}")
    if travel < min_travel:
        problems.append(f"it drove only {travel:.2f} m ({min_travel:g} m needed)")
    # A follower that halts at a corner may already have covered the travel: halting fails alone.
    if spent >= settle + STUCK and at_rest(samples, STUCK):
        problems.append(
            f"it stood still for the last {STUCK:g} s (a wall follower keeps going: at a "
            "corner it turns)"
        )
        broken = broken if broken[1] else (spent - STUCK, "stood still from here")
    trace = Trace.of(
        f"distance to the wall on the {side}",
        "m",
        thinned(every),
        low=low,
        high=high,
        judged_from=settle,
    )
    if distances and share < in_band:
        problems.append(
            f"the wall was in the band only {share:.0%} of the time ({in_band:.0%} needed)"
        )
        out = trace.first_outside()
        if not broken[1] and out is not None:
            broken = (out[0], f"first out of the band: in it {share:.0%} of the time")
    if travel < min_travel and not broken[1]:
        broken = (spent, f"only {travel:.2f} m driven")
    if broken[1]:
        trace = dataclasses.replace(trace, broken_at=broken[0], broken_why=broken[1])
    if problems:
        return Result(name, False, f"{began}; {figures}; " + "; ".join(problems), (trace,))
    return Result(name, True, f"{began}; {figures}; {touch_text(touch)}", (trace,))
