"""Probe ``turtle_frame``: the grader teleports a turtle to drawn poses; the learner's
``world -> turtle`` transform on /tf must follow each one.
"""

from __future__ import annotations

import math
import time

from app.exercises.probes.base import ProbeContext, draw, register_probe
from app.exercises.probes.tf import (
    WORLD_MAX,
    WORLD_MIN,
    FrameTap,
    Seen,
    pose_text,
    teleport,
)
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros.errors import Ros2Error
from app.ros.rotations import angle_between


def _frame_mistake(seen: Seen, x: float, y: float, theta: float, tol: float) -> str:
    """What a wrong transform most likely got wrong, in words."""
    if not seen.unit:
        return (
            "the rotation is not a unit quaternion: compute it from theta with sin/cos of theta/2"
        )
    if math.hypot(seen.x - y, seen.y - x) < tol and math.hypot(seen.x - x, seen.y - y) >= tol:
        return "x and y are swapped"
    if math.hypot(seen.x - x, seen.y - y) >= tol:
        return "the translation is not the turtle's position"
    if angle_between(seen.yaw, -theta) < 0.05:
        return "the heading has the wrong sign"
    return "the heading (rotation about z) is not the turtle's theta"


def _matches(
    seen: Seen | None, parent: str, after: float, pose: tuple[float, float, float], tol: float
) -> bool:
    x, y, theta = pose
    return (
        seen is not None
        and seen.arrival > after
        and seen.parent == parent
        and math.hypot(seen.x - x, seen.y - y) < tol
        and abs(seen.z) < tol
        and angle_between(seen.yaw, theta) < 0.02
        and seen.unit
    )


def _why_not(
    tap: FrameTap,
    seen: Seen | None,
    turtle: str,
    parent: str,
    after: float,
    pose: tuple[float, float, float],
    tol: float,
) -> str:
    """Why the last transform seen for ``turtle`` does not show it at ``pose``."""
    want = pose_text(*pose)
    if seen is None:
        heard = ", ".join(f"{a} -> {c}" for c, a in tap.children_of().items()) or "nothing"
        return f"no transform for the child frame '{turtle}' on /tf (heard: {heard})"
    if seen.parent != parent:
        return (
            f"'{turtle}' has the parent '{seen.parent}' on /tf; expected the parent "
            f"'{parent}' (header.frame_id is the parent, child_frame_id the turtle)"
        )
    if seen.arrival <= after:
        return f"teleported {turtle} to {want}; no new transform came after"
    got = pose_text(seen.x, seen.y, seen.yaw)
    return f"teleported {turtle} to {want}; /tf says {got}: {_frame_mistake(seen, *pose, tol)}"


@register_probe(
    "turtle_frame",
    required="",
    optional="turtle parent poses tolerance within",
    defaults={"x": [WORLD_MIN, WORLD_MAX], "y": [WORLD_MIN, WORLD_MAX], "theta": [-3.0, 3.0]},
    words="teleports the turtle to random poses; after each, /tf must carry parent -> turtle "
    "at that pose (position and heading)",
    draws="random turtle poses (x, y, theta)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    """Teleport the turtle to random poses; /tf must carry parent -> turtle at each pose."""
    turtle, parent = p.get("turtle", "turtle1"), p.get("parent", "world")
    tol, count = float(p.get("tolerance", 0.01)), int(p.get("poses", 4))
    name = f"frame {parent} -> {turtle} follows the pose"
    tap = FrameTap(ctx)
    tried: list[str] = []
    try:
        for _ in range(count):
            x, y, theta = (round(float(draw(ctx.rng, p[k])), 2) for k in ("x", "y", "theta"))
            after = time.monotonic() + 0.1  # a transform from before the teleport is no answer
            try:
                teleport(ctx, turtle, x, y, theta)
            except Ros2Error as exc:
                return Result(name, False, f"could not teleport {turtle}: {exc}")
            # `within` counts from the moment the turtle has moved: a teleport that
            # took that long on a loaded machine once used it all up before the
            # first look, and a correct node was told it sent nothing.
            deadline = time.monotonic() + float(p.get("within", 3.0))
            while not _matches(seen := tap.get(turtle), parent, after, (x, y, theta), tol):
                if time.monotonic() >= deadline:
                    why = _why_not(tap, seen, turtle, parent, after, (x, y, theta), tol)
                    return Result(name, False, why)
                ctx.call.sleep(0.05)
            tried.append(pose_text(x, y, theta))
        return Result(name, True, f"{count} random poses, each on /tf, e.g. {tried[0]}")
    finally:
        tap.close()
