"""Differential drive: velocity commands to wheel speeds, and odometry from encoders.

A differential-drive robot turns by driving its two wheels at different speeds.
With wheel radius ``r`` and wheel separation ``b``::

    left  = (v - w * b / 2) / r        right = (v + w * b / 2) / r      (rad/s)

Odometry runs the same equations backwards on what the wheel encoders measured.
It drifts, as on a real robot, because the driver's idea of ``r`` and ``b`` is
never exactly the truth, encoders count whole ticks, and wheels slip.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class TwistCheck:
    """A checked velocity command: what to drive, and what was wrong with the input."""

    linear: float
    angular: float
    problem: str = ""  # empty when the command was used as sent
    rejected: bool = False  # True: not finite, the command is ignored


def check_twist(linear: float, angular: float, max_linear: float, max_angular: float) -> TwistCheck:
    """NaN or infinite: rejected; faster than the robot can go: clamped, and said so."""
    if not (math.isfinite(linear) and math.isfinite(angular)):
        return TwistCheck(
            0.0,
            0.0,
            f"ignored a /cmd_vel with a non-finite value (linear.x={linear}, angular.z={angular})",
            rejected=True,
        )
    clamped_linear = max(-max_linear, min(max_linear, linear))
    clamped_angular = max(-max_angular, min(max_angular, angular))
    if (clamped_linear, clamped_angular) != (linear, angular):
        return TwistCheck(
            clamped_linear,
            clamped_angular,
            f"/cmd_vel (linear.x={linear:g} m/s, angular.z={angular:g} rad/s) is beyond the "
            f"robot's limits ({max_linear:g} m/s, {max_angular:g} rad/s): clamped to "
            f"({clamped_linear:g}, {clamped_angular:g})",
        )
    return TwistCheck(linear, angular)


def wheel_speeds(
    linear: float, angular: float, radius: float, separation: float
) -> tuple[float, float]:
    """(left, right) wheel speeds in rad/s for a body velocity (m/s, rad/s)."""
    half = angular * separation / 2.0
    return (linear - half) / radius, (linear + half) / radius


def quantize(angle: float, ticks_per_rev: int) -> float:
    """What an encoder with ``ticks_per_rev`` ticks reports for a wheel angle (rad)."""
    tick = 2.0 * math.pi / ticks_per_rev
    return math.floor(angle / tick) * tick


@dataclass
class Odometry:
    """Dead reckoning from wheel angles: the pose the robot believes it has.

    ``update`` takes the latest encoder angles (rad); it integrates the arc
    driven since the previous call (exact for a constant-curvature step).
    """

    radius: float
    separation: float
    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0
    linear: float = 0.0  # m/s, over the last update
    angular: float = 0.0  # rad/s
    _last: tuple[float, float] | None = field(default=None, repr=False)

    def reset(self, left: float, right: float) -> None:
        self.x = self.y = self.yaw = self.linear = self.angular = 0.0
        self._last = (left, right)

    def update(self, left: float, right: float, dt: float) -> None:
        if self._last is None:
            self._last = (left, right)
            return
        d_left = (left - self._last[0]) * self.radius
        d_right = (right - self._last[1]) * self.radius
        self._last = (left, right)
        distance = (d_left + d_right) / 2.0
        turn = (d_right - d_left) / self.separation
        # Move along the chord of the arc: heading halfway through the turn, and the
        # chord is shorter than the arc by sin(turn/2) / (turn/2).
        heading = self.yaw + turn / 2.0
        chord = distance * (math.sin(turn / 2.0) / (turn / 2.0) if abs(turn) > 1e-9 else 1.0)
        self.x += chord * math.cos(heading)
        self.y += chord * math.sin(heading)
        self.yaw = math.atan2(math.sin(self.yaw + turn), math.cos(self.yaw + turn))
        if dt > 0:
            self.linear = distance / dt
            self.angular = turn / dt


def odom_in_world(
    truth_position: Sequence[float] | np.ndarray,
    truth_quat_xyzw: Sequence[float] | np.ndarray,
    odom_x: float,
    odom_y: float,
    odom_yaw: float,
) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """Where the odom frame is in the world, so that world -> odom -> base_link is the truth.

    odom -> base_link is what the wheels believe; world -> base_link is where
    the robot really is. Their difference, world -> odom, is what a
    localization node would publish as map -> odom: the odometry's error,
    which grows as the robot drives.
    """
    truth = _matrix(*truth_quat_xyzw)
    half = odom_yaw / 2.0
    rotation = truth @ _matrix(0.0, 0.0, math.sin(half), math.cos(half)).T
    position = np.asarray(truth_position, dtype=np.float64) - rotation @ [odom_x, odom_y, 0.0]
    x, y, z = (float(v) for v in position)
    return (x, y, z), _quaternion(rotation)


def _matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _quaternion(m: np.ndarray) -> tuple[float, float, float, float]:
    """x, y, z, w of a rotation matrix (Shepperd's method: stable for every rotation)."""
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = (s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s)
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = ((m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4, (m[1, 0] - m[0, 1]) / s)
    x, y, z, w = (float(v) for v in q)
    return (x, y, z, w)
