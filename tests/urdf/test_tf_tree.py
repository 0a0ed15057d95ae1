"""The 3D view's TF store: poses in a fixed frame, tf2's refusals, loops and staleness."""

from __future__ import annotations

import math

import numpy as np
import pytest
from robot_state_publisher.urdf_tree import UrdfError
from scipy.spatial.transform import Rotation

from app.scene.robot_model import build_drawing
from app.scene.tf_tree import TfStore

IDENTITY = (0.0, 0.0, 0.0, 1.0)


def _quat(rotvec) -> tuple[float, float, float, float]:
    x, y, z, w = Rotation.from_rotvec(rotvec).as_quat()
    return (float(x), float(y), float(z), float(w))


def test_poses_compose_along_the_tree_in_any_fixed_frame() -> None:
    store = TfStore()
    rng = np.random.default_rng(5)
    parents = {"a": "world", "b": "a", "c": "b", "d": "a"}
    truth = {"world": np.eye(4)}
    for child, parent in parents.items():
        rotvec, xyz = rng.normal(size=3), rng.normal(size=3)
        m = np.eye(4)
        m[:3, :3] = Rotation.from_rotvec(rotvec).as_matrix()
        m[:3, 3] = xyz
        truth[child] = truth[parent] @ m
        assert store.add(parent, child, tuple(xyz), _quat(rotvec), static=False, now=0.0)
    assert store.roots() == ["world"]
    for fixed in ("world", "c", "d"):
        view = store.view(fixed, now=0.0)
        for frame, pose in view.poses.items():
            assert np.allclose(pose, np.linalg.inv(truth[fixed]) @ truth[frame], atol=1e-9)
        assert set(view.poses) == set(truth) and not view.problems


def test_nan_and_zero_quaternion_are_refused_with_tf2s_reason() -> None:
    store = TfStore()
    assert store.add("world", "a", (1.0, 0.0, 0.0), IDENTITY, static=False, now=0.0)
    assert not store.add("world", "a", (math.nan, 0.0, 0.0), IDENTITY, static=False, now=0.1)
    assert "TF_NAN_INPUT" in store.errors[-1] and '"a"' in store.errors[-1]
    assert not store.add("world", "a", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0), static=False)
    assert "TF_DENORMALIZED_QUATERNION" in store.errors[-1]
    assert np.allclose(store.view("world", now=0.1).poses["a"][:3, 3], (1.0, 0.0, 0.0))


def test_a_loop_and_an_unknown_fixed_frame_are_problems_not_crashes() -> None:
    store = TfStore()
    store.add("world", "a", (0, 0, 0), IDENTITY, static=True)
    store.add("p", "q", (0, 0, 0), IDENTITY, static=True)
    store.add("q", "p", (0, 0, 0), IDENTITY, static=True)
    view = store.view("world")
    assert "form a loop" in view.problems["p"] and "a" in view.poses
    missing = store.view("nowhere")
    assert not missing.poses and "Fixed Frame [nowhere] does not exist" in missing.problems["a"]


def test_dynamic_frames_go_stale_static_ones_never() -> None:
    store = TfStore()
    for i in range(10):
        store.add("world", "moving", (0, 0, 0), IDENTITY, static=False, now=i * 0.1)
    store.add("world", "fixed", (0, 0, 0), IDENTITY, static=True, now=0.0)
    assert not store.view("world", now=1.0).stale
    assert store.view("world", now=2.5).stale == frozenset({"moving"})


def test_robot_drawing_refuses_bad_descriptions_in_one_line() -> None:
    with pytest.raises(UrdfError, match="parent link \\[ghost\\]"):
        build_drawing(
            '<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="fixed">'
            '<parent link="ghost"/><child link="b"/></joint></robot>'
        )
    with pytest.raises(UrdfError, match="draws descriptions of up to"):
        build_drawing("<robot name='big'>" + " " * (10 * 1024 * 1024) + "</robot>")
    mesh_robot = build_drawing(
        '<robot name="m"><link name="a"><visual><geometry><mesh filename="/etc/passwd"/>'
        "</geometry></visual></link></robot>"
    )
    assert not mesh_robot.visuals  # only mesh files with a mesh extension are read
