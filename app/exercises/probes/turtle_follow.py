"""Probe ``turtle_follow``: the grader puts the leader turtle at random places, one after
another; the follower (steered by the learner's tf2 listener) must come close each time.
"""

from __future__ import annotations

import math
import time

from turtlesim.msg import Pose

from app.exercises.probes.base import ProbeContext, draw, register_probe
from app.exercises.probes.tf import WORLD_MAX, WORLD_MIN, teleport
from app.exercises.report import Result
from app.exercises.trace import Trace, thinned
from app.lessons.schema import Spec
from app.ros.errors import Ros2Error
from app.ros.monitor import TopicMonitor


def _distance(leader: TopicMonitor, follower: TopicMonitor) -> float | None:
    a, b = leader.message(), follower.message()
    if a is None or b is None:
        return None
    return math.hypot(a[1].x - b[1].x, a[1].y - b[1].y)


@register_probe(
    "turtle_follow",
    required="",
    optional="leader follower moves bound within spawn_within",
    defaults={
        "x": [WORLD_MIN, WORLD_MAX],
        "y": [WORLD_MIN, WORLD_MAX],
        "theta": [-3.0, 3.0],
        "min_jump": 3.0,
    },
    words="puts the leader turtle at random places, one after another; each time the "
    "follower must come within the bound of it",
    draws="a random path for the leader (places x, y, headings theta; each at least "
    "min_jump from the follower)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    """Put the leader at random places; each time the follower must come within ``bound``."""
    lead, follow = p.get("leader", "turtle1"), p.get("follower", "turtle2")
    bound, within = float(p.get("bound", 1.0)), float(p.get("within", 15.0))
    name = f"{follow} follows {lead}"
    node = ctx.call.node
    leader = TopicMonitor(node, f"/{lead}/pose", Pose, keep=5, qos=10)
    follower = TopicMonitor(node, f"/{follow}/pose", Pose, keep=5, qos=10)
    done: list[str] = []
    began = time.monotonic()
    points: list[tuple[float, float]] = []  # (s since the first move, distance) to plot

    def plotted(broken_at: float | None = None, why: str = "") -> tuple[Trace, ...]:
        if not points:
            return ()
        trace = Trace.of(
            f"distance from {follow} to {lead} (it jumps at each move)",
            "m",
            thinned(points),
            high=bound,
            broken_at=broken_at,
            broken_why=why,
            along="time (s)",
        )
        return (trace,)

    try:
        deadline = time.monotonic() + float(p.get("spawn_within", 10.0))
        while follower.message() is None or leader.message() is None:
            if time.monotonic() > deadline:
                return Result(
                    name, False, f"no pose on /{follow}/pose: spawn {follow} (the /spawn service)"
                )
            ctx.call.sleep(0.2)
        for move in range(int(p.get("moves", 2))):
            newest = follower.message()
            assert newest is not None
            fx, fy = newest[1].x, newest[1].y
            for _ in range(1000):  # a place at least min_jump from the follower: a real chase
                x = round(float(draw(ctx.rng, p["x"])), 2)
                y = round(float(draw(ctx.rng, p["y"])), 2)
                if math.hypot(x - fx, y - fy) >= float(p["min_jump"]):
                    break
            else:
                raise ValueError(f"no place in x, y is {p['min_jump']} m from the follower")
            try:
                teleport(ctx, lead, x, y, round(float(draw(ctx.rng, p["theta"])), 2))
            except Ros2Error as exc:
                return Result(name, False, f"could not teleport {lead}: {exc}")
            start = time.monotonic()
            ctx.call.sleep(0.3)
            trace = [_distance(leader, follower) or 0.0]
            closest = trace[0]
            while (d := _distance(leader, follower) or math.inf) > bound:
                closest = min(closest, d)
                if math.isfinite(d):
                    points.append((time.monotonic() - began, d))
                if time.monotonic() - start > within:
                    trace.append(d)
                    way = "grew" if trace[-1] > trace[0] + 0.2 else "did not close"
                    return Result(
                        name,
                        False,
                        f"move {move + 1}: put {lead} at ({x:.2f}, {y:.2f}); in {within:g} s the "
                        f"distance {way}: {trace[0]:.2f} m -> {trace[-1]:.2f} m (closest "
                        f"{closest:.2f} m, needed below {bound:g} m)",
                        plotted(time.monotonic() - began, f"move {move + 1}: not caught"),
                    )
                ctx.call.sleep(0.1)
            points.append((time.monotonic() - began, d))
            done.append(f"{trace[0]:.1f} m -> {d:.2f} m in {time.monotonic() - start:.1f} s")
        return Result(
            name, True, f"{follow} caught up after every move: {'; '.join(done)}", plotted()
        )
    finally:
        leader.close()
        follower.close()
