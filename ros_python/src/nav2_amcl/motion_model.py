"""Odometry motion models: move every particle by the odometry's step, with noise.

The differential model is *Probabilistic Robotics*' ``sample_motion_model_odometry``
(table 5.6): the step from the old odometry pose to the new one is a turn
(``rot1``), a straight move (``trans``) and another turn (``rot2``); each
particle gets these three with its own Gaussian noise, whose variance grows
with the motion: ``alpha1`` rotation from rotation, ``alpha2`` rotation from
translation, ``alpha3`` translation from translation, ``alpha4`` translation
from rotation. A step backwards would look like a half turn, so the noise of
a turn is taken from whichever of the turn and the turn plus pi is smaller
(as Nav2 does). The omnidirectional model adds ``alpha5``: sideways
translation noise.
"""

from __future__ import annotations

import math

import numpy as np


def normalize(angle: np.ndarray | float) -> np.ndarray | float:
    """An angle in [-pi, pi)."""
    return (np.asarray(angle) + math.pi) % (2.0 * math.pi) - math.pi


def angle_diff(a: float, b: float) -> float:
    """a - b, the short way round."""
    return float(normalize(a - b))


class DifferentialMotionModel:
    """``nav2_amcl::DifferentialMotionModel``."""

    def __init__(self, alpha1: float, alpha2: float, alpha3: float, alpha4: float) -> None:
        self.alpha1, self.alpha2, self.alpha3, self.alpha4 = alpha1, alpha2, alpha3, alpha4

    def odometry_update(
        self,
        poses: np.ndarray,
        pose: tuple[float, float, float],
        delta: tuple[float, float, float],
        rng: np.random.Generator,
    ) -> None:
        """Move ``poses`` (N, 3) in place: ``pose`` is the new odometry pose, ``delta`` the step."""
        x, y, yaw = pose
        dx, dy, dyaw = delta
        old_yaw = yaw - dyaw
        trans = math.hypot(dx, dy)
        rot1 = 0.0 if trans < 0.01 else angle_diff(math.atan2(dy, dx), old_yaw)
        rot2 = angle_diff(dyaw, rot1)
        # A step backwards is not a half turn: the smaller of rot and rot - pi.
        rot1_noise = min(abs(angle_diff(rot1, 0.0)), abs(angle_diff(rot1, math.pi)))
        rot2_noise = min(abs(angle_diff(rot2, 0.0)), abs(angle_diff(rot2, math.pi)))
        n = len(poses)
        a1, a2, a3, a4 = self.alpha1, self.alpha2, self.alpha3, self.alpha4
        rot1_hat = rot1 - rng.normal(0.0, math.sqrt(a1 * rot1_noise**2 + a2 * trans**2), n)
        trans_hat = trans - rng.normal(
            0.0, math.sqrt(a3 * trans**2 + a4 * rot1_noise**2 + a4 * rot2_noise**2), n
        )
        rot2_hat = rot2 - rng.normal(0.0, math.sqrt(a1 * rot2_noise**2 + a2 * trans**2), n)
        heading = poses[:, 2] + rot1_hat
        poses[:, 0] += trans_hat * np.cos(heading)
        poses[:, 1] += trans_hat * np.sin(heading)
        poses[:, 2] = normalize(poses[:, 2] + rot1_hat + rot2_hat)


class OmniMotionModel:
    """``nav2_amcl::OmniMotionModel``: a holonomic base, sideways noise from ``alpha5``."""

    def __init__(
        self, alpha1: float, alpha2: float, alpha3: float, alpha4: float, alpha5: float
    ) -> None:
        self.alpha1, self.alpha2, self.alpha3 = alpha1, alpha2, alpha3
        self.alpha4, self.alpha5 = alpha4, alpha5

    def odometry_update(
        self,
        poses: np.ndarray,
        pose: tuple[float, float, float],
        delta: tuple[float, float, float],
        rng: np.random.Generator,
    ) -> None:
        x, y, yaw = pose
        dx, dy, dyaw = delta
        old_yaw = yaw - dyaw
        trans = math.hypot(dx, dy)
        rot = dyaw
        # The step's direction relative to the robot's heading before it.
        bearing = angle_diff(math.atan2(dy, dx), old_yaw)
        n = len(poses)
        a1, a2, a3, a4, a5 = self.alpha1, self.alpha2, self.alpha3, self.alpha4, self.alpha5
        trans_sigma = math.sqrt(a3 * trans**2 + a1 * rot**2)
        rot_sigma = math.sqrt(a4 * rot**2 + a2 * trans**2)
        strafe_sigma = math.sqrt(a1 * rot**2 + a5 * trans**2)
        heading = poses[:, 2] + bearing
        trans_hat = trans + rng.normal(0.0, trans_sigma, n)
        rot_hat = rot + rng.normal(0.0, rot_sigma, n)
        strafe_hat = rng.normal(0.0, strafe_sigma, n)
        c, s = np.cos(heading), np.sin(heading)
        poses[:, 0] += trans_hat * c + strafe_hat * -s
        poses[:, 1] += trans_hat * s + strafe_hat * c
        poses[:, 2] = normalize(poses[:, 2] + rot_hat)
