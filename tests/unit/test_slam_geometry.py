"""Two-view geometry, alignment and the odometry on the synthetic room (no ROS)."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from nodes.common.frames import invert_transform, pose_to_matrix
from nodes.common.slam import (
    MonocularVO,
    absolute_trajectory_error,
    match_orb,
    project,
    relative_pose,
    triangulate,
    umeyama_alignment,
)
from nodes.common.synthetic_world import ROOM_MAX, ROOM_MIN, Intrinsics, SyntheticSequence

rng = np.random.default_rng(21)


@pytest.fixture(scope="module")
def sequence():
    return SyntheticSequence(length=300)


def test_rendered_frames_are_textured_images(sequence):
    frame = sequence.frame(0)
    assert frame.shape == (480, 640, 3) and frame.dtype == np.uint8
    corners = cv2.goodFeaturesToTrack(cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY), 500, 0.01, 10)
    assert len(corners) > 300  # plenty to track
    # The loop is closed: the last frame leads smoothly back to the first.
    np.testing.assert_allclose(sequence.pose(300), sequence.pose(0))
    for i in range(0, 300, 30):
        assert np.all(sequence.pose(i)[:3, 3] > ROOM_MIN) and np.all(
            sequence.pose(i)[:3, 3] < ROOM_MAX
        )


def test_triangulation_recovers_known_points():
    K = Intrinsics.default().matrix()
    points = rng.uniform((-1, -1, 3), (1, 1, 6), (50, 3))
    T_a = np.eye(4)
    T_b = pose_to_matrix(0.4, 0.05, 0.1, 0.02, -0.1, 0.03)
    pa, _ = project(K, T_a, points)
    pb, _ = project(K, T_b, points)
    np.testing.assert_allclose(triangulate(K, T_a, T_b, pa, pb), points, atol=1e-6)


def test_orb_matches_follow_a_known_image_shift(sequence):
    gray = cv2.cvtColor(sequence.frame(0), cv2.COLOR_BGR2GRAY)
    shifted = cv2.warpAffine(gray, np.float32([[1, 0, 7], [0, 1, -4]]), (640, 480))
    pts_a, pts_b = match_orb(gray, shifted)
    assert len(pts_a) > 200
    shift = pts_b - pts_a
    agree = np.linalg.norm(shift - (7, -4), axis=1) < 3.0  # coarse pyramid levels
    assert agree.mean() > 0.85


def test_essential_matrix_recovers_the_true_motion():
    K = Intrinsics.default().matrix()
    points = rng.uniform((-2, -1.5, 2), (2, 1.5, 6), (300, 3))
    T_a = np.eye(4)
    T_b = pose_to_matrix(0.3, -0.05, 0.1, 0.03, 0.12, -0.04)
    pa, _ = project(K, T_a, points)
    pb, _ = project(K, T_b, points)
    pb = pb + rng.normal(0, 0.3, pb.shape)  # sub-pixel noise
    pb[:30] += rng.uniform(-40, 40, (30, 2))  # and 10 % gross outliers
    R, t, inliers = relative_pose(pa.astype(np.float32), pb.astype(np.float32), K)
    assert inliers[30:].mean() > 0.9 and inliers[:30].mean() < 0.3
    truth = invert_transform(T_b) @ T_a  # maps camera a coordinates to camera b
    R_err = R.T @ truth[:3, :3]
    assert math.degrees(math.acos(np.clip((np.trace(R_err) - 1) / 2, -1, 1))) < 0.2
    direction = truth[:3, 3] / np.linalg.norm(truth[:3, 3])
    assert math.degrees(math.acos(np.clip(direction @ t, -1, 1))) < 2.0


def test_umeyama_undoes_a_similarity():
    source = rng.normal(size=(100, 3))
    R = pose_to_matrix(0, 0, 0, 0.3, -0.5, 2.0)[:3, :3]
    target = 2.5 * source @ R.T + [1.0, -2.0, 0.5]
    scale, R_est, t = umeyama_alignment(source, target)
    assert math.isclose(scale, 2.5, rel_tol=1e-9)
    np.testing.assert_allclose(R_est, R, atol=1e-9)
    np.testing.assert_allclose(t, [1.0, -2.0, 0.5], atol=1e-9)
    report = absolute_trajectory_error(source, target)
    assert report["ate_rmse"] < 1e-9


def test_odometry_follows_the_first_part_of_the_loop(sequence):
    vo = MonocularVO(sequence.intrinsics.matrix())
    states = [vo.process(sequence.frame(i)).state for i in range(60)]
    assert "initialised" in states and "lost" not in states
    assert len(vo.points) > 300
    indices = sorted(vo.poses)
    assert len(indices) == 60  # frames before initialisation are located afterwards
    estimated = np.array([vo.poses[i][:3, 3] for i in indices])
    truth = np.array([sequence.pose(i)[:3, 3] for i in indices])
    assert absolute_trajectory_error(estimated, truth)["ate_percent"] < 2.0
