"""The 3D view's particle layer: amcl's guesses as one batch of arrows on the floor (no DDS)."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from geometry_msgs.msg import Pose, PoseArray
from nav2_msgs.msg import Particle, ParticleCloud

from app.scene.particle_cloud import (
    MAX_LENGTH,
    MIN_LENGTH,
    SEGMENTS_PER_PARTICLE,
    ParticleCloudLayer,
    arrow_lengths,
    arrow_segments,
    spread,
)


class FakeScene:
    """Records add_line_segments calls; handles take new points and can be removed."""

    def __init__(self) -> None:
        self.nodes: dict[str, Any] = {}
        self.adds = 0

    def add_line_segments(self, name: str, points: np.ndarray, colors: Any, **props: Any) -> Any:
        self.adds += 1
        handle = SimpleNamespace(points=points, colors=colors, props=props)
        handle.remove = lambda: self.nodes.pop(name, None)
        self.nodes[name] = handle
        return handle


def pose(x: float, y: float, yaw: float) -> Pose:
    p = Pose()
    p.position.x, p.position.y = x, y
    p.orientation.z, p.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return p


def cloud(poses: list[tuple[float, float, float]], weights=None, frame="map") -> ParticleCloud:
    msg = ParticleCloud()
    msg.header.frame_id = frame
    weights = weights or [1.0 / len(poses)] * len(poses)
    msg.particles = [Particle(pose=pose(*p), weight=w) for p, w in zip(poses, weights, strict=True)]
    return msg


def layer_on(scene: FakeScene, **kwargs: Any) -> ParticleCloudLayer:
    return ParticleCloudLayer(node=None, server=SimpleNamespace(scene=scene), **kwargs)  # type: ignore[arg-type]


def test_each_pose_is_an_arrow_along_its_heading_flat_on_the_floor():
    x, y = np.array([1.0, -2.0]), np.array([0.5, 3.0])
    yaw = np.array([0.0, math.pi / 2])
    segments = arrow_segments(x, y, yaw, np.array([0.1, 0.2]), lift=0.03)
    assert segments.shape == (2 * SEGMENTS_PER_PARTICLE, 2, 3) and segments.dtype == np.float32
    assert np.allclose(segments[:, :, 2], 0.03)  # flat, just above the floor
    shaft0, shaft1 = segments[0], segments[SEGMENTS_PER_PARTICLE]
    assert shaft0 == pytest.approx(np.array([[1.0, 0.5, 0.03], [1.1, 0.5, 0.03]]), abs=1e-6)
    assert shaft1 == pytest.approx(np.array([[-2.0, 3.0, 0.03], [-2.0, 3.2, 0.03]]), abs=1e-6)
    for barb in segments[1:3]:  # the barbs start at the tip and point back, one each side
        assert barb[0] == pytest.approx(shaft0[1], abs=1e-6)
        assert barb[1][0] < 1.1
    assert sorted([segments[1][1][1], segments[2][1][1]])[0] < 0.5 < segments[1][1][1]


def test_heavier_particles_have_longer_arrows():
    assert arrow_lengths(np.array([0.0, 0.5, 1.0]), 3) == pytest.approx(
        [MIN_LENGTH, (MIN_LENGTH + MAX_LENGTH) / 2, MAX_LENGTH]
    )
    assert arrow_lengths(None, 2) == pytest.approx([MAX_LENGTH, MAX_LENGTH])  # a PoseArray
    assert arrow_lengths(np.array([0.0, 0.0]), 2) == pytest.approx([MAX_LENGTH, MAX_LENGTH])


def test_spread_is_the_rms_distance_from_the_mean():
    x, y = np.array([-1.0, 1.0, 0.0, 0.0]), np.array([0.0, 0.0, -1.0, 1.0])
    assert spread(x, y) == pytest.approx(1.0)
    assert spread(x, y, np.array([1.0, 1.0, 0.0, 0.0])) == pytest.approx(1.0)
    assert spread(np.array([2.0]), np.array([3.0])) == 0.0


def test_thousands_of_particles_are_one_primitive_under_their_frame():
    rng = np.random.default_rng(1)
    xy = rng.normal(0.0, 0.3, size=(2000, 2))
    yaws = rng.uniform(-math.pi, math.pi, 2000)
    scene = FakeScene()
    layer = layer_on(scene)
    try:
        layer.draw(cloud([(a, b, c) for (a, b), c in zip(xy, yaws, strict=True)]))
        (name,) = scene.nodes
        assert name == "/tf_view/frames/map/particle_cloud"
        drawn = scene.nodes[name]
        assert drawn.points.shape == (2000 * SEGMENTS_PER_PARTICLE, 2, 3)
        shafts = drawn.points[::SEGMENTS_PER_PARTICLE]
        assert shafts[:, 0, :2] == pytest.approx(xy.astype(np.float32), abs=1e-5)
        direction = shafts[:, 1, :2] - shafts[:, 0, :2]
        assert np.arctan2(direction[:, 1], direction[:, 0]) == pytest.approx(yaws, abs=1e-4)
        assert layer.note.startswith("2000 particles, spread 0.4")
        assert layer.describe().endswith("in `map`")
        layer.draw(cloud([(0.0, 0.0, 0.0)] * 2000))  # the same count: the points change in place
        assert scene.adds == 1 and "spread 0.00 m" in layer.note
        layer.draw(cloud([(0.0, 0.0, 0.0)], frame="odom"))  # another frame: the old arrows go
        assert list(scene.nodes) == ["/tf_view/frames/odom/particle_cloud"]
    finally:
        layer.worker.stop()


def test_a_pose_array_draws_too_and_bad_poses_are_left_out():
    msg = PoseArray()
    msg.header.frame_id = "map"
    msg.poses = [pose(0.0, 0.0, 0.0), pose(float("nan"), 0.0, 0.0), pose(1.0, 0.0, 1.0)]
    scene = FakeScene()
    layer = layer_on(scene, frame_known=lambda frame: frame == "odom")
    try:
        layer.draw(msg)
        (drawn,) = scene.nodes.values()
        assert len(drawn.points) == 2 * SEGMENTS_PER_PARTICLE
        assert layer.note.startswith("2 poses") and "1 with a NaN" in layer.note
        assert "not on TF" in layer.describe()
        layer.draw(PoseArray())  # nothing in it: nothing drawn, said so
        assert not scene.nodes and "no poses" in layer.describe()
    finally:
        layer.worker.stop()


def test_clouds_as_they_arrive_read_from_their_bytes_as_rclpy_would():
    from rclpy.serialization import serialize_message

    from app.scene.particle_cloud import decode_poses, poses_of

    msg = cloud([(1.0, 2.0, 0.5), (-1.0, 0.5, -2.0), (0.0, 0.0, 3.0)], weights=[0.2, 0.3, 0.5])
    frame, rows = decode_poses(serialize_message(msg), weighted=True)  # type: ignore[misc]
    table, weights = poses_of(msg)
    assert frame == "map" and rows[:, :7] == pytest.approx(table)
    assert rows[:, 7] == pytest.approx(weights)
    array = PoseArray(poses=[pose(1.0, 2.0, 0.5)])
    array.header.frame_id = "odom"
    frame, rows = decode_poses(serialize_message(array), weighted=False)  # type: ignore[misc]
    assert frame == "odom" and rows.shape == (1, 7) and rows[0, :2] == pytest.approx([1.0, 2.0])
    assert decode_poses(serialize_message(ParticleCloud()), weighted=True)[1].shape == (0, 8)  # type: ignore[index]
    assert decode_poses(b"\x00\x01\x00\x00" + bytes(3), weighted=True) is None  # cut short
    scene = FakeScene()
    layer = layer_on(scene)
    try:
        layer.draw((ParticleCloud, serialize_message(msg)))
        (drawn,) = scene.nodes.values()
        assert len(drawn.points) == 3 * SEGMENTS_PER_PARTICLE
        assert layer.describe().startswith("3 particles, spread")
    finally:
        layer.worker.stop()
