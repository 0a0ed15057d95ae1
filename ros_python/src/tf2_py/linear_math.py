"""Rigid-transform maths on plain tuples, as tf2's LinearMath does it.

A rotation is a unit quaternion ``(x, y, z, w)`` (ROS order), a translation
``(x, y, z)``. Plain floats, not numpy: the lookups compose a handful of
transforms, where numpy's per-call cost would dominate.
"""

from __future__ import annotations

import math

Quat = tuple[float, float, float, float]
Vec = tuple[float, float, float]

IDENTITY_Q: Quat = (0.0, 0.0, 0.0, 1.0)
ZERO_V: Vec = (0.0, 0.0, 0.0)


def quat_multiply(a: Quat, b: Quat) -> Quat:
    """The rotation ``b`` followed by ``a`` (Hamilton product ``a * b``)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def quat_inverse(q: Quat) -> Quat:
    """The inverse of a unit quaternion (its conjugate)."""
    return (-q[0], -q[1], -q[2], q[3])


def quat_rotate(q: Quat, v: Vec) -> Vec:
    """``v`` rotated by the unit quaternion ``q``."""
    x, y, z, w = q
    vx, vy, vz = v
    # t = 2 * (u x v); v' = v + w t + u x t
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (
        vx + w * tx + (y * tz - z * ty),
        vy + w * ty + (z * tx - x * tz),
        vz + w * tz + (x * ty - y * tx),
    )


def quat_normalize(q: Quat) -> Quat:
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


def quat_norm2(q: Quat) -> float:
    return q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]


def slerp(a: Quat, b: Quat, t: float) -> Quat:
    """Spherical interpolation from ``a`` (t=0) to ``b`` (t=1) along the shorter arc."""
    d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
    if d < 0.0:
        b = (-b[0], -b[1], -b[2], -b[3])
        d = -d
    if d > 0.9999995:  # nearly the same rotation: sin(theta) ~ 0, lerp is exact enough
        s0, s1 = 1.0 - t, t
    else:
        theta = math.acos(d)
        inv = 1.0 / math.sin(theta)
        s0 = math.sin((1.0 - t) * theta) * inv
        s1 = math.sin(t * theta) * inv
    x = s0 * a[0] + s1 * b[0]
    y = s0 * a[1] + s1 * b[1]
    z = s0 * a[2] + s1 * b[2]
    w = s0 * a[3] + s1 * b[3]
    n = 1.0 / math.sqrt(x * x + y * y + z * z + w * w)
    return (x * n, y * n, z * n, w * n)


def lerp(a: Vec, b: Vec, t: float) -> Vec:
    return (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t)


def compose(q_a: Quat, t_a: Vec, q_b: Quat, t_b: Vec) -> tuple[Quat, Vec]:
    """The transform ``A * B``: first ``B``, then ``A`` (inlined: lookups call it per link)."""
    ax, ay, az, aw = q_a
    bx, by, bz, bw = q_b
    vx, vy, vz = t_b
    tx = 2.0 * (ay * vz - az * vy)
    ty = 2.0 * (az * vx - ax * vz)
    tz = 2.0 * (ax * vy - ay * vx)
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ), (
        vx + aw * tx + (ay * tz - az * ty) + t_a[0],
        vy + aw * ty + (az * tx - ax * tz) + t_a[1],
        vz + aw * tz + (ax * ty - ay * tx) + t_a[2],
    )


def invert(q: Quat, t: Vec) -> tuple[Quat, Vec]:
    """The inverse of the transform ``(q, t)``."""
    qi = quat_inverse(q)
    r = quat_rotate(qi, t)
    return qi, (-r[0], -r[1], -r[2])


def quaternion_from_euler(roll: float, pitch: float, yaw: float) -> Quat:
    """tf2's ``setRPY``: fixed axes X (roll), then Y (pitch), then Z (yaw), in radians."""
    cr, sr = math.cos(roll * 0.5), math.sin(roll * 0.5)
    cp, sp = math.cos(pitch * 0.5), math.sin(pitch * 0.5)
    cy, sy = math.cos(yaw * 0.5), math.sin(yaw * 0.5)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def matrix_from_quaternion(q: Quat) -> list[list[float]]:
    """The 3x3 rotation matrix (rows) of a quaternion, normalising it first."""
    x, y, z, w = q
    s = 2.0 / (x * x + y * y + z * z + w * w)
    xs, ys, zs = x * s, y * s, z * s
    wx, wy, wz = w * xs, w * ys, w * zs
    xx, xy, xz = x * xs, x * ys, x * zs
    yy, yz, zz = y * ys, y * zs, z * zs
    return [
        [1.0 - (yy + zz), xy - wz, xz + wy],
        [xy + wz, 1.0 - (xx + zz), yz - wx],
        [xz - wy, yz + wx, 1.0 - (xx + yy)],
    ]


def euler_from_matrix(m: list[list[float]]) -> tuple[float, float, float]:
    """(roll, pitch, yaw) of a rotation matrix, as tf2's ``getEulerYPR`` reads it."""
    if abs(m[2][0]) >= 1.0:
        yaw = 0.0
        if m[2][0] < 0.0:
            pitch = math.pi / 2.0
            roll = math.atan2(m[0][1], m[0][2])
        else:
            pitch = -math.pi / 2.0
            roll = math.atan2(-m[0][1], -m[0][2])
        return roll, pitch, yaw
    pitch = -math.asin(m[2][0])
    c = math.cos(pitch)
    roll = math.atan2(m[2][1] / c, m[2][2] / c)
    yaw = math.atan2(m[1][0] / c, m[0][0] / c)
    return roll, pitch, yaw


def euler_from_quaternion(q: Quat) -> tuple[float, float, float]:
    return euler_from_matrix(matrix_from_quaternion(q))
