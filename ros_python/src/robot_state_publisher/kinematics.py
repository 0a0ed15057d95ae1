"""The maths of robot_state_publisher: a joint's transform is its origin times its motion.

A URDF joint places its child link at ``origin`` (``xyz`` then fixed-axis
``rpy``: roll about x, pitch about y, yaw about z) in the parent link's frame,
then moves it along or about ``axis`` (a unit vector in the joint frame) by
the joint position ``q``: a rotation of ``q`` radians for revolute and
continuous joints, a translation of ``q`` metres for prismatic ones, nothing
for fixed ones. Plain functions on 4x4 numpy matrices, testable without ROS.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

ROTATING = frozenset({"revolute", "continuous"})
SLIDING = frozenset({"prismatic"})
MOVABLE = ROTATING | SLIDING


def rpy_to_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """3x3 rotation of URDF's ``rpy``: Rz(yaw) @ Ry(pitch) @ Rx(roll) (fixed axes x, y, z)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def origin_matrix(xyz: Sequence[float], rpy: Sequence[float]) -> np.ndarray:
    """4x4 transform of a URDF ``<origin xyz rpy>``."""
    matrix = np.eye(4)
    matrix[:3, :3] = rpy_to_matrix(*rpy)
    matrix[:3, 3] = xyz
    return matrix


def axis_angle_matrix(axis: Sequence[float], angle: float) -> np.ndarray:
    """3x3 rotation of ``angle`` radians about the unit vector ``axis`` (Rodrigues)."""
    x, y, z = (float(v) for v in axis)
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def joint_motion(joint_type: str, axis: Sequence[float], position: float) -> np.ndarray:
    """4x4 motion a joint adds at ``position`` (identity for fixed and unsupported types)."""
    motion = np.eye(4)
    if joint_type in ROTATING:
        motion[:3, :3] = axis_angle_matrix(axis, position)
    elif joint_type in SLIDING:
        motion[:3, 3] = np.asarray(axis, dtype=float) * position
    return motion


def joint_transform(
    origin: np.ndarray, joint_type: str, axis: Sequence[float], position: float = 0.0
) -> np.ndarray:
    """Parent link -> child link: ``origin @ motion(position)``."""
    return origin @ joint_motion(joint_type, axis, position)


def mimic_position(leader: float, multiplier: float = 1.0, offset: float = 0.0) -> float:
    """A mimic joint's position follows its leader: ``leader * multiplier + offset``."""
    return leader * multiplier + offset


def matrix_to_quaternion(rotation: np.ndarray) -> tuple[float, float, float, float]:
    """Unit quaternion ``(x, y, z, w)`` (ROS order) of a 3x3 rotation, ``w >= 0``."""
    m = np.asarray(rotation, dtype=float)
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        w, x = 0.25 * s, (m[2, 1] - m[1, 2]) / s
        y, z = (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        w, x = (m[2, 1] - m[1, 2]) / s, 0.25 * s
        y, z = (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        w, x = (m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s
        y, z = 0.25 * s, (m[1, 2] + m[2, 1]) / s
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        w, x = (m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s
        y, z = (m[1, 2] + m[2, 1]) / s, 0.25 * s
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    sign = -1.0 if w < 0.0 else 1.0
    return (sign * x / norm, sign * y / norm, sign * z / norm, sign * w / norm)
