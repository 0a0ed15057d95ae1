"""Kinematics of the classroom's simulated 4-joint arm.

Geometry (metres, radians), all joints revolute::

    joint 1  base_yaw        about the vertical z axis of base_link
    joint 2  shoulder_pitch  elevation of the upper arm above the horizontal
    joint 3  elbow_pitch     bend of the forearm relative to the upper arm
    joint 4  wrist_pitch     bend of the gripper relative to the forearm

    BASE_HEIGHT = 0.10   base_link origin (on the table) up to the shoulder axis
    UPPER_ARM   = 0.30   shoulder axis to elbow axis
    FOREARM     = 0.25   elbow axis to wrist axis
    GRIPPER     = 0.08   wrist axis to the fingertips (the end effector point)

After the base turns by ``q1`` the rest of the arm moves in one vertical plane.
In that plane, with ``r`` the horizontal distance from the base axis and ``z``
the height, each link points at the sum of the pitch angles before it::

    r = U cos(q2) + F cos(q2 + q3) + G cos(q2 + q3 + q4)
    z = H + U sin(q2) + F sin(q2 + q3) + G sin(q2 + q3 + q4)

Inverse kinematics keeps the gripper pointing straight down (the usual
top-down grasp: ``q2 + q3 + q4 = -pi/2``), which removes the redundancy of
the fourth joint. The wrist centre is then ``GRIPPER`` above the target, and
the shoulder and elbow form a two-link planar arm solved with the law of
cosines. Elbow-up is tried first, elbow-down second.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from nodes.common.frames import make_transform, rot_y, rot_z

BASE_HEIGHT = 0.10
UPPER_ARM = 0.30
FOREARM = 0.25
GRIPPER = 0.08

JOINT_NAMES = ("base_yaw", "shoulder_pitch", "elbow_pitch", "wrist_pitch")
# (lower, upper) limits of each joint, radians.
JOINT_LIMITS = (
    (-math.pi, math.pi),
    (-math.pi / 4, 3 * math.pi / 4),
    (-5 * math.pi / 6, 5 * math.pi / 6),
    (-math.pi, math.pi),
)
TOOL_DOWN = -math.pi / 2  # pitch of the gripper when it points at the table
MIN_HEIGHT = 0.0  # the table top: targets below it are refused


class Unreachable(ValueError):
    """The arm cannot put its gripper on this target; ``reason`` says why."""

    def __init__(self, target, reason: str) -> None:
        self.target = tuple(float(v) for v in target)
        self.reason = reason
        x, y, z = self.target
        super().__init__(f"target ({x:.3f}, {y:.3f}, {z:.3f}) m is unreachable: {reason}")


@dataclass(frozen=True)
class ArmPose:
    """Where the end effector is: position (m) and orientation (3x3, base frame)."""

    position: np.ndarray
    rotation: np.ndarray

    def matrix(self) -> np.ndarray:
        return make_transform(self.rotation, self.position)


def link_points(joints) -> np.ndarray:
    """Positions of base, shoulder, elbow, wrist and fingertip: (5, 3), base frame.

    Handy for drawing the arm as a polyline.
    """
    q1, q2, q3, q4 = (float(v) for v in joints)
    a2, a3, a4 = q2, q2 + q3, q2 + q3 + q4
    r = np.cumsum(
        [0.0, 0.0, UPPER_ARM * math.cos(a2), FOREARM * math.cos(a3), GRIPPER * math.cos(a4)]
    )
    z = np.cumsum(
        [0.0, BASE_HEIGHT, UPPER_ARM * math.sin(a2), FOREARM * math.sin(a3), GRIPPER * math.sin(a4)]
    )
    return np.stack([r * math.cos(q1), r * math.sin(q1), z], axis=1)


def forward_kinematics(joints) -> ArmPose:
    """Fingertip pose for the joint angles ``(q1, q2, q3, q4)``.

    The end-effector frame has its x axis along the gripper (the approach
    direction) and its y axis horizontal, to the arm's left.
    """
    q1, q2, q3, q4 = (float(v) for v in joints)
    position = link_points((q1, q2, q3, q4))[-1]
    # Yaw about z, then pitch the x axis down by the summed pitch angles.
    rotation = rot_z(q1) @ rot_y(-(q2 + q3 + q4))
    return ArmPose(position=position, rotation=rotation)


def within_limits(joints) -> bool:
    return all(
        lo - 1e-9 <= q <= hi + 1e-9 for q, (lo, hi) in zip(joints, JOINT_LIMITS, strict=True)
    )


def inverse_kinematics(target, *, seed_yaw: float = 0.0) -> np.ndarray:
    """Joint angles that put the fingertip on ``target`` (x, y, z) pointing down.

    Raises :class:`Unreachable` with the reason when no solution exists.
    ``seed_yaw`` is used only when the target lies on the base axis, where any
    yaw works.
    """
    x, y, z = (float(v) for v in target)
    if not all(math.isfinite(v) for v in (x, y, z)):
        raise Unreachable((x, y, z), "coordinates are not finite numbers")
    if z < MIN_HEIGHT:
        raise Unreachable((x, y, z), f"it is below the table (z < {MIN_HEIGHT} m)")
    r = math.hypot(x, y)
    q1 = math.atan2(y, x) if r > 1e-9 else seed_yaw
    # Wrist centre in the arm's vertical plane, relative to the shoulder axis.
    wr = r
    wz = z + GRIPPER - BASE_HEIGHT
    dist_sq = wr * wr + wz * wz
    cos_elbow = (dist_sq - UPPER_ARM**2 - FOREARM**2) / (2.0 * UPPER_ARM * FOREARM)
    if cos_elbow > 1.0 + 1e-12:
        reach = UPPER_ARM + FOREARM
        raise Unreachable(
            (x, y, z),
            f"the wrist would be {math.sqrt(dist_sq):.3f} m from the shoulder, "
            f"beyond the arm's reach of {reach:.2f} m",
        )
    if cos_elbow < -1.0 - 1e-12:
        raise Unreachable((x, y, z), "it is too close to the shoulder to fold the arm onto")
    cos_elbow = max(-1.0, min(1.0, cos_elbow))
    for elbow_sign in (-1.0, 1.0):  # negative elbow angle = elbow up
        q3 = elbow_sign * math.acos(cos_elbow)
        q2 = math.atan2(wz, wr) - math.atan2(
            FOREARM * math.sin(q3), UPPER_ARM + FOREARM * math.cos(q3)
        )
        q4 = TOOL_DOWN - q2 - q3
        q4 = (q4 + math.pi) % (2 * math.pi) - math.pi
        joints = np.array([q1, q2, q3, q4])
        if within_limits(joints):
            return joints
    raise Unreachable((x, y, z), "every solution breaks a joint limit")


def is_reachable(target) -> bool:
    try:
        inverse_kinematics(target)
    except Unreachable:
        return False
    return True


def step_towards(current, goal, max_step: float) -> np.ndarray:
    """Move each joint at most ``max_step`` rad towards ``goal`` (a smooth, rate-limited move).

    All joints arrive together: the step is scaled so the joint with the
    longest way to go moves ``max_step`` and the others proportionally less.
    """
    current = np.asarray(current, dtype=float)
    delta = np.asarray(goal, dtype=float) - current
    largest = float(np.max(np.abs(delta))) if delta.size else 0.0
    if largest <= max_step:
        return current + delta
    return current + delta * (max_step / largest)
