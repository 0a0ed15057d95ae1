"""Rigid transforms as plain numpy: quaternions, 4x4 matrices, roll-pitch-yaw.

ROS orders quaternions x, y, z, w; viser orders them w, x, y, z. Every
conversion between the two goes through this module so the order is decided
in one place.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

# A 3- or 4-vector as a tuple, a list or a numpy array.
Vector = Sequence[float] | np.ndarray


def as_xyz(v: Vector) -> tuple[float, float, float]:
    """A 3-vector as the plain float triple viser's positions take."""
    x, y, z = (float(c) for c in v)
    return (x, y, z)


def ros_to_wxyz(x: float, y: float, z: float, w: float) -> tuple[float, float, float, float]:
    """A ROS quaternion (x, y, z, w) as viser's (w, x, y, z), normalised."""
    q = np.array([w, x, y, z], dtype=np.float64)
    norm = float(np.linalg.norm(q))
    if norm < 1e-12:  # an all-zero quaternion (a common publisher mistake) means identity
        return (1.0, 0.0, 0.0, 0.0)
    q /= norm
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def wxyz_to_ros(wxyz: Vector) -> tuple[float, float, float, float]:
    """viser's (w, x, y, z) as ROS's (x, y, z, w)."""
    w, x, y, z = (float(v) for v in wxyz)
    return (x, y, z, w)


def quat_to_matrix(wxyz: Vector) -> np.ndarray:
    """3x3 rotation matrix of a unit quaternion given as (w, x, y, z)."""
    w, x, y, z = (float(v) for v in wxyz)
    n = w * w + x * x + y * y + z * z
    s = 0.0 if n < 1e-12 else 2.0 / n
    return np.array(
        [
            [1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
            [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
            [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)],
        ]
    )


def matrix_to_quat(rot: np.ndarray) -> tuple[float, float, float, float]:
    """(w, x, y, z) of a 3x3 rotation matrix (Shepperd's method, stable near 180 deg)."""
    m = np.asarray(rot, dtype=np.float64)
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        s = 2.0 * np.sqrt(trace + 1.0)
        q = (0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = ((m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s)
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = ((m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s)
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = ((m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s)
    arr = np.array(q)
    if arr[0] < 0:  # one canonical sign keeps displayed numbers from flipping
        arr = -arr
    arr /= np.linalg.norm(arr)
    return (float(arr[0]), float(arr[1]), float(arr[2]), float(arr[3]))


def rpy_to_quat(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(w, x, y, z) for fixed-axis roll about x, then pitch about y, then yaw about z (ROS RPY)."""
    cr, sr = np.cos(roll / 2), np.sin(roll / 2)
    cp, sp = np.cos(pitch / 2), np.sin(pitch / 2)
    cy, sy = np.cos(yaw / 2), np.sin(yaw / 2)
    return (
        float(cr * cp * cy + sr * sp * sy),
        float(sr * cp * cy - cr * sp * sy),
        float(cr * sp * cy + sr * cp * sy),
        float(cr * cp * sy - sr * sp * cy),
    )


def quat_to_rpy(wxyz: Vector) -> tuple[float, float, float]:
    """Inverse of :func:`rpy_to_quat` (pitch clamped at +-90 deg)."""
    r = quat_to_matrix(wxyz)
    pitch = float(np.arcsin(np.clip(-r[2, 0], -1.0, 1.0)))
    roll = float(np.arctan2(r[2, 1], r[2, 2]))
    yaw = float(np.arctan2(r[1, 0], r[0, 0]))
    return (roll, pitch, yaw)


def make_matrix(wxyz: Vector, position: Vector) -> np.ndarray:
    """4x4 homogeneous matrix T such that p_parent = T @ p_child."""
    t = np.eye(4)
    t[:3, :3] = quat_to_matrix(wxyz)
    t[:3, 3] = np.asarray(position, dtype=np.float64)
    return t


def apply(t: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Transform (N, 3) points by the 4x4 matrix ``t``."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return pts @ t[:3, :3].T + t[:3, 3]


def format_matrix(t: np.ndarray, digits: int = 3) -> str:
    """A 4x4 matrix as aligned text rows, for a code block in the panel."""
    rows = [" ".join(f"{v:+.{digits}f}" for v in row) for row in np.asarray(t)]
    return "\n".join(f"[ {row} ]" for row in rows)


def quat_z_to(direction: Vector) -> tuple[float, float, float, float]:
    """(w, x, y, z) rotating +z onto ``direction`` (for cylinders and arrows along a segment)."""
    d = np.asarray(direction, dtype=np.float64)
    n = float(np.linalg.norm(d))
    if n < 1e-12:
        return (1.0, 0.0, 0.0, 0.0)
    d /= n
    axis = np.cross([0.0, 0.0, 1.0], d)
    s = float(np.linalg.norm(axis))
    c = float(d[2])
    if s < 1e-9:
        return (1.0, 0.0, 0.0, 0.0) if c > 0 else (0.0, 1.0, 0.0, 0.0)
    angle = np.arctan2(s, c)
    axis /= s
    h = np.sin(angle / 2)
    return (float(np.cos(angle / 2)), float(axis[0] * h), float(axis[1] * h), float(axis[2] * h))
