"""Probe ``point_transform``: random points in one frame must come back in another (a fixed
pose), with the usual slips (no translation, transposed rotation, ...) named.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from app.exercises.probes.base import ProbeContext, register_probe
from app.exercises.probes.topics import SEND_QOS, exchange, fmt, listen, wait_subscribed
from app.exercises.report import Result
from app.lessons.schema import Spec


def _pose_matrices(pose: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """(R, t) of a frame placed at x, y, z and turned by fixed-axis roll, pitch, yaw."""
    from nodes.common.frames import rpy_to_matrix

    rotation = rpy_to_matrix(pose["roll"], pose["pitch"], pose["yaw"])
    return rotation, np.array([pose["x"], pose["y"], pose["z"]], dtype=float)


def _transform_slips(pose: dict[str, float]) -> list[tuple[str, Callable[[np.ndarray], Any]]]:
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


@register_probe(
    "point_transform",
    required="publish output pose",
    optional="points tolerance frame_id input_frame_id",
    words="sends random points in the camera's frame; each must come back in the base's "
    "frame (p_base = R p + t for the camera's pose), with the right frame_id",
    draws="random points (x, y in [-0.3, 0.3] m, z in [0.3, 1.0] m)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    """Send random PointStamped in one frame; expect them in another (a fixed pose)."""
    from geometry_msgs.msg import PointStamped

    node = ctx.call.node
    in_topic, out_topic = p["publish"], p["output"]
    pose = {k: float(p["pose"][k]) for k in ("x", "y", "z", "roll", "pitch", "yaw")}
    rotation, t = _pose_matrices(pose)
    tolerance = p.get("tolerance", 1e-3)
    frame = p.get("frame_id", "")
    name = f"transform {in_topic} -> {out_topic}"
    publisher = node.create_publisher(PointStamped, in_topic, SEND_QOS)
    monitor = listen(ctx, out_topic, PointStamped)
    try:
        why = wait_subscribed(ctx, publisher, in_topic)
        if why:
            return Result(name, False, why)
        count = p.get("points", 5)
        for i in range(1, count + 1):
            point = np.array(
                [
                    round(ctx.rng.uniform(-0.3, 0.3), 3),
                    round(ctx.rng.uniform(-0.3, 0.3), 3),
                    round(ctx.rng.uniform(0.3, 1.0), 3),
                ]
            )
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
        return Result(
            name, True, f"{count} random points transformed right (within {tolerance:g} m)"
        )
    finally:
        monitor.close()
        node.destroy_publisher(publisher)
