"""What the tf2 probes share (registers no kind): a reader of /tf and /tf_static, turtle
teleports, and the frame maths (yaw of a quaternion, where a URDF joint puts its child).
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass

from tf2_msgs.msg import TFMessage
from turtlesim.srv import TeleportAbsolute

from app.exercises.probes.base import ProbeContext
from app.ros.calls import call_service
from app.ros.rotations import yaw_of
from app.ros.tf_sources import STATIC_QOS, TF_QOS

WORLD_MIN, WORLD_MAX = 1.5, 9.5  # teleport targets: inside turtlesim's 11 m world, off the walls


@dataclass(frozen=True)
class Seen:
    """One transform as it arrived: when, its parent, translation and yaw."""

    arrival: float
    parent: str
    x: float
    y: float
    z: float
    yaw: float
    unit: bool  # the quaternion has length 1 (within 1e-3)
    static: bool = False  # came on /tf_static


class FrameTap:
    """Every transform on /tf and /tf_static, newest per child frame (executor thread writes)."""

    def __init__(self, ctx: ProbeContext, static_only: bool = False) -> None:
        self._node = ctx.call.node
        self._lock = threading.Lock()
        self.newest: dict[str, Seen] = {}
        self._subs = [
            self._node.create_subscription(TFMessage, "/tf_static", self._on_static, STATIC_QOS)
        ]
        if not static_only:
            self._subs.append(self._node.create_subscription(TFMessage, "/tf", self._on_tf, TF_QOS))

    def _on_static(self, msg: TFMessage) -> None:
        self._on_tf(msg, static=True)

    def _on_tf(self, msg: TFMessage, static: bool = False) -> None:
        now = time.monotonic()
        with self._lock:
            for t in msg.transforms:
                v, r = t.transform.translation, t.transform.rotation
                length = math.sqrt(r.x**2 + r.y**2 + r.z**2 + r.w**2)
                self.newest[t.child_frame_id] = Seen(
                    now,
                    t.header.frame_id,
                    v.x,
                    v.y,
                    v.z,
                    yaw_of(r.x, r.y, r.z, r.w),
                    abs(length - 1.0) < 1e-3,
                    static,
                )

    def get(self, child: str) -> Seen | None:
        with self._lock:
            return self.newest.get(child)

    def children_of(self) -> dict[str, str]:
        with self._lock:
            return {child: seen.parent for child, seen in self.newest.items()}

    def close(self) -> None:
        for sub in self._subs:
            self._node.destroy_subscription(sub)


def teleport(ctx: ProbeContext, turtle: str, x: float, y: float, theta: float) -> None:
    request = TeleportAbsolute.Request(x=x, y=y, theta=theta)
    call_service(  # absolute: sending it twice puts the turtle in the same place
        ctx.call,
        f"/{turtle}/teleport_absolute",
        TeleportAbsolute,
        request,
        timeout=3.0,
        resend_unanswered=True,
    )


def pose_text(x: float, y: float, yaw: float) -> str:
    return f"(x={x:.2f}, y={y:.2f}, yaw={yaw:.2f})"


def _axis_angle(axis: tuple[float, float, float], angle: float) -> tuple[float, ...]:
    """The quaternion (x, y, z, w) turning ``angle`` about ``axis`` (normalised here)."""
    n = math.sqrt(sum(a * a for a in axis)) or 1.0
    s = math.sin(angle / 2.0) / n
    return (axis[0] * s, axis[1] * s, axis[2] * s, math.cos(angle / 2.0))


def _rotate(q: tuple[float, ...], v: tuple[float, float, float]) -> tuple[float, float, float]:
    """``v`` turned by the unit quaternion ``q``."""
    x, y, z, w = q
    # v' = v + 2w (u x v) + 2 u x (u x v), u = (x, y, z)
    cx, cy, cz = y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0]
    dx, dy, dz = y * cz - z * cy, z * cx - x * cz, x * cy - y * cx
    return (v[0] + 2 * (w * cx + dx), v[1] + 2 * (w * cy + dy), v[2] + 2 * (w * cz + dz))


def expected_joint_pose(
    joint_type: str,
    origin: tuple[float, float, float],
    axis: tuple[float, float, float],
    value: float,
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> tuple[tuple[float, float, float], tuple[float, ...]]:
    """Where a point ``offset`` of the child sits in the parent, and the child's rotation.

    URDF: the child frame is the joint origin, then the motion along/about the axis.
    """
    if joint_type == "prismatic":
        n = math.sqrt(sum(a * a for a in axis)) or 1.0
        shift = tuple(o + a / n * value for o, a in zip(origin, axis, strict=True))
        point = tuple(p + q for p, q in zip(shift, offset, strict=True))
        return (point[0], point[1], point[2]), (0.0, 0.0, 0.0, 1.0)
    q = _axis_angle(axis, value)
    turned = _rotate(q, offset)
    point = tuple(o + t for o, t in zip(origin, turned, strict=True))
    return (point[0], point[1], point[2]), q
