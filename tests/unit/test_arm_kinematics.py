"""The arm's forward and inverse kinematics (no ROS)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nodes.common.arm_kinematics import (
    BASE_HEIGHT,
    FOREARM,
    GRIPPER,
    JOINT_LIMITS,
    UPPER_ARM,
    Unreachable,
    forward_kinematics,
    inverse_kinematics,
    is_reachable,
    link_points,
    step_towards,
    within_limits,
)


def random_reachable_targets(count: int, seed: int = 5) -> np.ndarray:
    """Fingertip positions of random elbow-up arm poses with the gripper pointing down."""
    rng = np.random.default_rng(seed)
    targets = []
    while len(targets) < count:
        q1 = rng.uniform(-math.pi, math.pi)
        q2 = rng.uniform(0.0, math.pi / 2)
        q3 = rng.uniform(-2.4, -0.2)
        q4 = -math.pi / 2 - q2 - q3
        tip = forward_kinematics((q1, q2, q3, q4)).position
        if tip[2] >= 0.0 and math.hypot(tip[0], tip[1]) > 0.02:
            targets.append(tip)
    return np.array(targets)


def test_link_lengths_by_hand():
    # Arm stretched horizontally, gripper in line: reach = sum of the three links.
    tip = forward_kinematics((0.0, 0.0, 0.0, 0.0)).position
    np.testing.assert_allclose(tip, [UPPER_ARM + FOREARM + GRIPPER, 0.0, BASE_HEIGHT], atol=1e-12)
    # Turned 90 degrees left, upper arm straight up, forearm and gripper forward.
    tip = forward_kinematics((math.pi / 2, math.pi / 2, -math.pi / 2, 0.0)).position
    np.testing.assert_allclose(tip, [0.0, FOREARM + GRIPPER, BASE_HEIGHT + UPPER_ARM], atol=1e-12)
    assert link_points((0, 0, 0, 0)).shape == (5, 3)


def test_end_effector_orientation_points_the_x_axis_along_the_gripper():
    pose = forward_kinematics((0.4, 0.9, -1.5, -0.9))
    approach = pose.rotation[:, 0]
    points = link_points((0.4, 0.9, -1.5, -0.9))
    direction = (points[-1] - points[-2]) / GRIPPER
    np.testing.assert_allclose(approach, direction, atol=1e-12)
    np.testing.assert_allclose(pose.rotation.T @ pose.rotation, np.eye(3), atol=1e-12)


@pytest.mark.parametrize("target", list(random_reachable_targets(200)))
def test_ik_round_trip_through_forward_kinematics(target):
    joints = inverse_kinematics(target)
    assert within_limits(joints)
    pose = forward_kinematics(joints)
    np.testing.assert_allclose(pose.position, target, atol=1e-9)
    # The gripper points straight down.
    np.testing.assert_allclose(pose.rotation[:, 0], [0.0, 0.0, -1.0], atol=1e-9)


@pytest.mark.parametrize(
    ("target", "reason"),
    [
        ((1.0, 0.0, 0.2), "beyond the arm's reach"),
        ((0.0, -0.9, 0.1), "beyond the arm's reach"),
        ((0.3, 0.0, -0.05), "below the table"),
        ((0.02, 0.0, 0.12), "breaks a joint limit"),  # folded onto its own base
        ((math.nan, 0.0, 0.1), "not finite"),
        ((0.0, 0.02, 0.02), "too close"),
    ],
)
def test_unreachable_targets_are_rejected_with_a_reason(target, reason):
    with pytest.raises(Unreachable) as info:
        inverse_kinematics(target)
    assert reason in str(info.value)
    assert not is_reachable(target)


def test_random_far_targets_are_all_rejected():
    rng = np.random.default_rng(2)
    directions = rng.normal(size=(100, 3))
    directions[:, 2] = np.abs(directions[:, 2])
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    shoulder = np.array([0.0, 0.0, BASE_HEIGHT])
    # Past the reach of upper arm + forearm + gripper from the shoulder: impossible.
    far = shoulder + directions * (UPPER_ARM + FOREARM + GRIPPER + 0.01)
    assert not any(is_reachable(t) for t in far)


def test_step_towards_is_rate_limited_and_arrives():
    current, goal = np.zeros(4), np.array([1.0, -0.5, 0.25, 0.0])
    steps = 0
    while not np.allclose(current, goal):
        nxt = step_towards(current, goal, 0.1)
        assert np.max(np.abs(nxt - current)) <= 0.1 + 1e-12
        current, steps = nxt, steps + 1
    assert steps == 10  # the longest way (1 rad) at 0.1 rad per step


def test_joint_limits_are_ordered():
    assert all(lo < hi for lo, hi in JOINT_LIMITS)
