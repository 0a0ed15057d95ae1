"""The maths under the TF checks and the URDF probe, against pytransform3d (independent).

Quaternions are (x, y, z, w) as in ROS; pytransform3d writes (w, x, y, z).
"""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
from pytransform3d import rotations as pr

from app.exercises.probes.tf import expected_joint_pose
from app.ros.rotations import angle_between, quaternion_from_rpy, rotation_angle, rpy_of, yaw_of

RNG = random.Random(23)


def as_p3d(q: tuple[float, ...]) -> np.ndarray:
    return np.array([q[3], q[0], q[1], q[2]])


@pytest.mark.parametrize("seed", range(20))
def test_rpy_quaternion_matches_fixed_axis_rotations(seed):
    rng = random.Random(seed)
    roll, pitch, yaw = rng.uniform(-3, 3), rng.uniform(-1.5, 1.5), rng.uniform(-3, 3)
    q = quaternion_from_rpy(roll, pitch, yaw)
    # ROS rpy: R = Rz(yaw) Ry(pitch) Rx(roll), i.e. extrinsic x, y, z
    matrix = pr.matrix_from_euler([roll, pitch, yaw], 0, 1, 2, extrinsic=True)
    assert np.allclose(pr.matrix_from_quaternion(as_p3d(q)), matrix, atol=1e-9)
    assert np.allclose(rpy_of(*q), (roll, pitch, yaw), atol=1e-9)
    # the probe's yaw normalises first: a quaternion of the wrong length gives the same yaw
    assert yaw_of(*(2.0 * v for v in q)) == pytest.approx(yaw, abs=1e-9)


def test_rotation_angle_and_heading_difference():
    a, b = quaternion_from_rpy(0, 0, 0.3), quaternion_from_rpy(0, 0, -0.4)
    assert rotation_angle(a, b) == pytest.approx(0.7)
    assert rotation_angle(a, tuple(-v for v in a)) == pytest.approx(0.0, abs=1e-6)  # q and -q
    assert angle_between(3.1, -3.1) == pytest.approx(2 * math.pi - 6.2)


@pytest.mark.parametrize("joint_type", ["revolute", "prismatic"])
def test_expected_joint_pose_matches_homogeneous_transforms(joint_type):
    for _ in range(20):
        origin = tuple(RNG.uniform(-1, 1) for _ in range(3))
        axis = tuple(RNG.uniform(-1, 1) for _ in range(3))
        offset = tuple(RNG.uniform(-1, 1) for _ in range(3))
        value = RNG.uniform(-2, 2)
        point, q = expected_joint_pose(joint_type, origin, axis, value, offset)  # type: ignore[arg-type]
        unit = np.array(axis) / np.linalg.norm(axis)
        motion = np.eye(4)
        if joint_type == "prismatic":
            motion[:3, 3] = unit * value
        else:
            motion[:3, :3] = pr.matrix_from_axis_angle([*unit, value])
        joint = np.eye(4)
        joint[:3, 3] = origin
        want = (joint @ motion @ np.array([*offset, 1.0]))[:3]
        assert np.allclose(point, want, atol=1e-9)
        assert np.allclose(pr.matrix_from_quaternion(as_p3d(q)), motion[:3, :3], atol=1e-9)
