"""Probe ``static_frame``: the grader sets the learner's frame parameters to drawn names and
offsets, then joins /tf_static late and reads the frame there.
"""

from __future__ import annotations

import math
import time

from app.exercises.probes.base import ProbeContext, draw, register_probe
from app.exercises.probes.tf import FrameTap, Seen
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros import params
from app.ros.errors import Ros2Error
from app.ros.rotations import angle_between

CHILD_WORDS = ("lidar", "camera", "imu", "gps", "sonar", "bumper", "antenna")
PARENT_WORDS = ("world", "map", "odom", "base_link")


def _late_joiner_frames(ctx: ProbeContext, within: float, child: str) -> dict[str, Seen]:
    """What a fresh transient-local /tf_static subscriber receives within ``within`` s."""
    tap = FrameTap(ctx, static_only=True)
    try:
        deadline = time.monotonic() + within
        while time.monotonic() < deadline and tap.get(child) is None:
            ctx.call.sleep(0.1)
        return dict(tap.newest)
    finally:
        tap.close()


@register_probe(
    "static_frame",
    required="",
    optional="node settle within",
    defaults={
        "child_frames": list(CHILD_WORDS),
        "child_number": [10, 99],
        "parent_frames": list(PARENT_WORDS),
        "x": [-2.0, 2.0],
        "y": [-2.0, 2.0],
        "z": [-2.0, 2.0],
        "yaw": [-3.0, 3.0],
    },
    words="sets the node's frame parameters to random names and offsets; a subscriber that "
    "joins /tf_static late must then get that frame",
    draws="a random frame: parent from parent_frames, child from child_frames with a "
    "number (child_number), offsets x, y, z and heading yaw",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    """Set the node's frame parameters to drawn values; a late /tf_static joiner must get it."""
    target = p.get("node", ctx.learner_node)
    child = f"{draw(ctx.rng, p['child_frames'])}_{draw(ctx.rng, p['child_number'])}"
    parent = str(draw(ctx.rng, p["parent_frames"]))
    values: dict[str, float | str] = {"child_frame": child, "parent_frame": parent}
    for axis in ("x", "y", "z", "yaw"):
        values[axis] = float(draw(ctx.rng, p[axis]))
    name = f"static frame {parent} -> {child}"
    asked = ", ".join(f"{k}={v!r}" for k, v in values.items())
    dynamic = FrameTap(ctx)  # hears /tf too: a frame sent there is a likely mistake
    try:
        for key, value in values.items():
            try:
                ok, reason = params.set_value(ctx.call, target, key, value)
            except Ros2Error as exc:
                return Result(name, False, f"could not set the parameter {key}: {exc}")
            if not ok:
                return Result(name, False, f"{target} refused {key}={value!r}: {reason}")
        ctx.call.sleep(float(p.get("settle", 1.5)))  # sent by now; the next reader joins late
        frames = _late_joiner_frames(ctx, float(p.get("within", 8.0)), child)
        seen = frames.get(child)
        if seen is None:
            heard = ", ".join(sorted(frames)) or "nothing"
            on_tf = dynamic.get(child)
            if on_tf is not None and not on_tf.static:
                return Result(
                    name,
                    False,
                    f"set {asked}; '{child}' went out on /tf, not /tf_static: a subscriber "
                    "that joins later never gets it (use StaticTransformBroadcaster)",
                )
            return Result(
                name,
                False,
                f"set {asked}; a subscriber that joined /tf_static late got no '{child}' "
                f"(it got: {heard}): send the frame again whenever the parameters change",
            )
        want = (float(values["x"]), float(values["y"]), float(values["z"]))
        got = f"(x={seen.x:.3f}, y={seen.y:.3f}, z={seen.z:.3f}, yaw={seen.yaw:.3f})"
        if seen.parent != parent:
            return Result(name, False, f"set {asked}; '{child}' has the parent '{seen.parent}'")
        if math.dist((seen.x, seen.y, seen.z), want) > 1e-3:
            return Result(name, False, f"set {asked}; a late joiner got {got}: wrong translation")
        if not seen.unit or angle_between(seen.yaw, float(values["yaw"])) > 1e-3:
            return Result(
                name,
                False,
                f"set {asked}; a late joiner got {got}: the heading (yaw) is wrong"
                + ("" if seen.unit else ", and the quaternion is not of length 1"),
            )
        return Result(name, True, f"set {asked}; a late joiner got {parent} -> {child} {got}")
    finally:
        dynamic.close()
