"""Probe ``point_transform``: random points in one frame must come back in another (a fixed
pose), with the usual slips (no translation, transposed rotation, ...) named.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from app.exercises.probes.base import ProbeContext, draw, is_drawn, register_probe
from app.exercises.probes.topics import SEND_QOS, exchange, fmt, listen, wait_subscribed
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros import params
from app.ros.errors import Ros2Error


def _pose_matrices(pose: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """(R, t) of a frame placed at x, y, z and turned by fixed-axis roll, pitch, yaw."""
    from nodes.common.frames import rpy_to_matrix

    rotation = rpy_to_matrix(pose["roll"], pose["pitch"], pose["yaw"])
    return rotation, np.array([pose["x"], pose["y"], pose["z"]], dtype=float)


def _transform_slips(
    pose: dict[str, float],
) -> list[tuple[str, Callable[[np.ndarray], np.ndarray]]]:
    """The usual ways to get ``p_base = R p + t`` wrong, each with what to say."""
    from nodes.common.frames import rot_x, rot_y, rot_z

    rotation, t = _pose_matrices(pose)
    xyz_order = rot_x(pose["roll"]) @ rot_y(pose["pitch"]) @ rot_z(pose["yaw"])
    return [
        ("the point came back unchanged: it was not transformed", lambda p: p),
        (
            "the translation is missing: add the camera's position (x, y, z) after rotating",
            lambda p: rotation @ p,
        ),
        (
            "the rotation is applied the wrong way round (its transpose, or inverse); "
            "p_base = R @ p_camera + t with R = Rz(yaw) @ Ry(pitch) @ Rx(roll)",
            lambda p: rotation.T @ p + t,
        ),
        (
            "this is the inverse transform (base to camera); the point comes from the "
            "camera, so use T_base_camera itself",
            lambda p: rotation.T @ (p - t),
        ),
        (
            "the rotations are combined in the wrong order; with fixed axes it is "
            "R = Rz(yaw) @ Ry(pitch) @ Rx(roll)",
            lambda p: xyz_order @ p + t,
        ),
        ("no rotation was applied, only the translation", lambda p: p + t),
    ]


POSE_KEYS = ("x", "y", "z", "roll", "pitch", "yaw")


def _set_pose(ctx: ProbeContext, target: str, prefix: str, pose: dict[str, float]) -> str:
    """Set the node's pose parameters (``prefix`` + x, y, ...); '' or why it failed."""
    for key in POSE_KEYS:
        name = f"{prefix}{key}"
        try:
            ok, reason = params.set_value(ctx.call, target, name, pose[key])
        except Ros2Error as exc:
            return f"could not set the parameter {name}: {exc}"
        if not ok:
            return f"{target} refused {name}={pose[key]!r}: {reason or 'no reason given'}"
    return ""


def _pose_now(ctx: ProbeContext, target: str, prefix: str) -> dict[str, float] | None:
    """The node's pose parameters before the grader sets them, if it has them all."""
    try:
        values = params.get_values(ctx.call, target, [f"{prefix}{k}" for k in POSE_KEYS])
        found = [params.python_value(v) for v in values]
    except Ros2Error:
        return None
    if len(found) != len(POSE_KEYS) or not all(isinstance(v, (int, float)) for v in found):
        return None
    return {k: float(v) for k, v in zip(POSE_KEYS, found, strict=True)}


@register_probe(
    "point_transform",
    required="publish output pose",
    optional="points tolerance frame_id input_frame_id pose_parameters node",
    defaults={"point_x": [-0.3, 0.3], "point_y": [-0.3, 0.3], "point_z": [0.3, 1.0]},
    words="sends random points in the camera's frame; each must come back in the base's "
    "frame (p_base = R p + t for the camera's pose), with the right frame_id",
    draws="random points in the camera's frame (point_x, point_y, point_z), and a random "
    "camera pose where the pose gives ranges (set on the node's pose parameters)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    """Send random PointStamped in one frame; expect them in another.

    A ``pose`` with ranges is drawn, and set on the node's parameters named
    ``pose_parameters`` + x, y, z, roll, pitch, yaw before the points go out.
    """
    from geometry_msgs.msg import PointStamped

    node = ctx.call.node
    target = p.get("node", ctx.learner_node)
    in_topic, out_topic = p["publish"], p["output"]
    pose = {k: float(draw(ctx.rng, p["pose"][k])) for k in POSE_KEYS}
    name = f"transform {in_topic} -> {out_topic}"
    old_pose = None
    if "pose_parameters" in p.fields:
        prefix = p["pose_parameters"]
        old_pose = _pose_now(ctx, target, prefix)
        why = _set_pose(ctx, target, prefix, pose)
        if why:
            return Result(name, False, why)
    elif any(is_drawn(p["pose"][k]) for k in POSE_KEYS):
        raise ValueError("a drawn pose needs pose_parameters (the node learns it from them)")
    rotation, t = _pose_matrices(pose)
    tolerance = p.get("tolerance", 1e-3)
    frame = p.get("frame_id", "")
    publisher = node.create_publisher(PointStamped, in_topic, SEND_QOS)
    monitor = listen(ctx, out_topic, PointStamped)
    try:
        why = wait_subscribed(ctx, publisher, in_topic)
        if why:
            return Result(name, False, why)
        count = p.get("points", 5)
        for i in range(1, count + 1):
            point = np.array([float(draw(ctx.rng, p[f"point_{k}"])) for k in "xyz"])
            msg = PointStamped()
            msg.header.frame_id = p.get("input_frame_id", "camera")
            msg.point.x, msg.point.y, msg.point.z = (float(v) for v in point)
            answer = exchange(ctx, publisher, monitor, msg, i)
            shown = f"point {i} {fmt(point)}"
            if answer is None:
                return Result(
                    name, False, f"sent {shown} on {in_topic}; nothing came back on {out_topic}"
                )
            got = np.array([answer.point.x, answer.point.y, answer.point.z])
            want = rotation @ point + t
            error = float(np.linalg.norm(got - want))
            if error > tolerance:
                text = (
                    f"sent {shown}: {out_topic} gave {fmt(got)}, expected {fmt(want)} "
                    f"(off by {error:.3f} m)"
                )
                if old_pose is not None and old_pose != pose:
                    old_rotation, old_t = _pose_matrices(old_pose)
                    if np.linalg.norm(got - (old_rotation @ point + old_t)) <= tolerance:
                        return Result(
                            name,
                            False,
                            f"{text}: that is where the camera pose the node started with puts "
                            f"it; the grader set the pose parameters to {_pose_text(pose)}: "
                            "read them when a point arrives",
                        )
                for diagnosis, slip in _transform_slips(pose):
                    if np.linalg.norm(got - np.asarray(slip(point))) <= tolerance:
                        return Result(name, False, f"{text}: {diagnosis}")
                return Result(name, False, text)
            if frame and answer.header.frame_id != frame:
                return Result(
                    name,
                    False,
                    f"the coordinates are right, but header.frame_id is "
                    f"{answer.header.frame_id!r}; expected {frame!r}",
                )
        where = f" for the camera at {_pose_text(pose)}" if old_pose is not None else ""
        return Result(
            name, True, f"{count} random points transformed right{where} (within {tolerance:g} m)"
        )
    finally:
        monitor.close()
        node.destroy_publisher(publisher)


def _pose_text(pose: dict[str, float]) -> str:
    return ", ".join(f"{k}={pose[k]:g}" for k in POSE_KEYS)
