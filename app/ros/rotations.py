"""Rotations as TF carries them (quaternions x, y, z, w), in the ROS conventions.

One home for the maths that lesson checks, exercise probes and views share:
a yaw to compare headings, roll-pitch-yaw as ``tf2_echo`` prints it, the
quaternion the tf2 tutorials build from roll-pitch-yaw, and the angle between
two rotations.
"""

from __future__ import annotations

import math

Quaternion = tuple[float, ...]  # (x, y, z, w)


def yaw_of(x: float, y: float, z: float, w: float) -> float:
    """Yaw (rotation about z) of a quaternion, normalised first: a quaternion of the
    wrong length cannot hide a wrong angle."""
    n = math.sqrt(x * x + y * y + z * z + w * w) or 1.0
    x, y, z, w = x / n, y / n, z / n, w / n
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def rpy_of(x: float, y: float, z: float, w: float) -> tuple[float, float, float]:
    """Roll, pitch, yaw (fixed axes, ROS convention) of a quaternion."""
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    return roll, pitch, yaw_of(x, y, z, w)


def quaternion_from_rpy(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """x, y, z, w of R = Rz(yaw) Ry(pitch) Rx(roll), as the tf2 tutorials compute it."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def rotation_angle(a: Quaternion, b: Quaternion) -> float:
    """The angle (rad) of the rotation between two unit quaternions (x, y, z, w)."""
    dot = abs(sum(p * q for p, q in zip(a, b, strict=True)))
    return 2.0 * math.acos(min(1.0, dot))


def angle_between(a: float, b: float) -> float:
    """The smaller angle (rad, 0..pi) between two headings."""
    return abs(math.atan2(math.sin(a - b), math.cos(a - b)))
