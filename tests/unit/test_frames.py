"""Homogeneous transforms and the camera-to-base conversion (no ROS)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nodes.common.frames import (
    BODY_FROM_OPTICAL,
    OPTICAL_FROM_BODY,
    invert_transform,
    matrix_to_quaternion,
    matrix_to_rpy,
    pose_to_matrix,
    quaternion_to_matrix,
    rpy_to_matrix,
    transform_points,
)

rng = np.random.default_rng(11)


def test_identity_pose_changes_nothing():
    np.testing.assert_allclose(
        transform_points(pose_to_matrix(0, 0, 0, 0, 0, 0), [1, 2, 3]), [1, 2, 3]
    )


def test_translation_then_yaw_by_hand():
    # A frame 1 m along x, turned 90 degrees left: its x axis is the parent's y axis.
    T = pose_to_matrix(1.0, 0.0, 0.0, 0.0, 0.0, math.pi / 2)
    np.testing.assert_allclose(transform_points(T, [1.0, 0.0, 0.0]), [1.0, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(transform_points(T, [0.0, 1.0, 0.0]), [0.0, 0.0, 0.0], atol=1e-12)


def test_camera_looking_down_matches_the_coordinate_transform_node():
    # The default mount of coordinate_transform: 0.25 m ahead, 0.7 m up, roll = pi.
    T_base_cam = pose_to_matrix(0.25, 0.0, 0.7, math.pi, 0.0, 0.0)
    p_cam = np.array([0.1, -0.05, 0.6])  # right, up in the image, 0.6 m deep
    np.testing.assert_allclose(transform_points(T_base_cam, p_cam), [0.35, 0.05, 0.1], atol=1e-12)


def test_rpy_is_fixed_axis_roll_then_pitch_then_yaw():
    roll, pitch, yaw = 0.3, -0.2, 1.1
    R = rpy_to_matrix(roll, pitch, yaw)
    c, s = math.cos, math.sin
    Rx = np.array([[1, 0, 0], [0, c(roll), -s(roll)], [0, s(roll), c(roll)]])
    Ry = np.array([[c(pitch), 0, s(pitch)], [0, 1, 0], [-s(pitch), 0, c(pitch)]])
    Rz = np.array([[c(yaw), -s(yaw), 0], [s(yaw), c(yaw), 0], [0, 0, 1]])
    np.testing.assert_allclose(R, Rz @ Ry @ Rx, atol=1e-12)
    np.testing.assert_allclose(matrix_to_rpy(R), (roll, pitch, yaw), atol=1e-12)


@pytest.mark.parametrize("trial", range(20))
def test_inverse_and_composition(trial):
    a = pose_to_matrix(*rng.uniform(-2, 2, 3), *rng.uniform(-math.pi, math.pi, 3))
    b = pose_to_matrix(*rng.uniform(-2, 2, 3), *rng.uniform(-math.pi, math.pi, 3))
    np.testing.assert_allclose(invert_transform(a) @ a, np.eye(4), atol=1e-12)
    points = rng.uniform(-1, 1, (10, 3))
    chained = transform_points(a, transform_points(b, points))
    np.testing.assert_allclose(transform_points(a @ b, points), chained, atol=1e-12)
    np.testing.assert_allclose(
        transform_points(invert_transform(a), transform_points(a, points)), points, atol=1e-12
    )


@pytest.mark.parametrize("trial", range(20))
def test_quaternion_round_trip(trial):
    R = rpy_to_matrix(*rng.uniform(-math.pi, math.pi, 3))
    q = matrix_to_quaternion(R)
    assert math.isclose(np.linalg.norm(q), 1.0) and q[3] >= 0.0
    np.testing.assert_allclose(quaternion_to_matrix(*q), R, atol=1e-12)


def test_quaternion_of_half_turns():
    np.testing.assert_allclose(
        matrix_to_quaternion(rpy_to_matrix(math.pi, 0, 0)), (1, 0, 0, 0), atol=1e-12
    )
    np.testing.assert_allclose(
        matrix_to_quaternion(rpy_to_matrix(0, 0, math.pi / 2)),
        (0, 0, math.sqrt(0.5), math.sqrt(0.5)),
        atol=1e-12,
    )


def test_optical_frame_axes():
    # Looking forward along the body's x: the optical z axis.
    np.testing.assert_allclose(OPTICAL_FROM_BODY @ [1, 0, 0], [0, 0, 1])
    np.testing.assert_allclose(BODY_FROM_OPTICAL @ [0, 1, 0], [0, 0, -1])  # image "down"
