"""The 3D view's path layer: the planner's /plan as one line above the floor (no DDS)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Path

from app.scene.nav_path import LIFT, PathLayer, path_length, polyline_segments


class FakeScene:
    def __init__(self) -> None:
        self.nodes: dict[str, Any] = {}
        self.adds = 0

    def add_line_segments(self, name: str, points: np.ndarray, colors: Any, **props: Any) -> Any:
        self.adds += 1
        handle = SimpleNamespace(points=points, colors=colors, props=props)
        handle.remove = lambda: self.nodes.pop(name, None)
        self.nodes[name] = handle
        return handle


def path_msg(points: list[tuple[float, float]], frame: str = "map") -> Path:
    msg = Path()
    msg.header.frame_id = frame
    for x, y in points:
        p = PoseStamped()
        p.header.frame_id = frame
        p.pose.position.x, p.pose.position.y = x, y
        p.pose.orientation.w = 1.0
        msg.poses.append(p)
    return msg


def test_a_path_becomes_a_polyline_joining_its_poses_in_order():
    points = np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [3.0, 4.0, 0.0]])
    segments = polyline_segments(points, lift=0.05)
    assert segments.shape == (2, 2, 3)
    assert segments[0] == pytest.approx(np.array([[0, 0, 0.05], [3, 0, 0.05]]))
    assert segments[1] == pytest.approx(np.array([[3, 0, 0.05], [3, 4, 0.05]]))
    assert path_length(points) == pytest.approx(7.0)


def test_the_layer_draws_the_plan_under_its_frame_and_says_how_long_it_is():
    scene = FakeScene()
    layer = PathLayer(node=None, server=SimpleNamespace(scene=scene))  # type: ignore[arg-type]
    try:
        line = [(0.1 * i, 0.0) for i in range(142)]
        layer.draw(path_msg(line))
        (name,) = scene.nodes
        assert name == "/tf_view/frames/map/nav_path"
        drawn = scene.nodes[name]
        assert drawn.points.shape == (141, 2, 3)
        assert drawn.points[:, :, 2] == pytest.approx(np.full((141, 2), LIFT))
        assert drawn.props["thickness_units"] == "screen"
        assert layer.describe() == "142 poses, 14.1 m, in `map`"
        layer.draw(path_msg([(0.0, 0.1 * i) for i in range(142)]))  # replanned: moved in place
        assert scene.adds == 1 and drawn.points[-1, 1, 1] == pytest.approx(14.1)
        layer.draw(path_msg([]))  # Nav2's empty path: the line goes
        assert not scene.nodes and layer.describe() == "an empty path (no plan)"
        layer.draw(path_msg([(0.0, 0.0), (1.0, 0.0)], frame="odom"))
        assert list(scene.nodes) == ["/tf_view/frames/odom/nav_path"]
    finally:
        layer.worker.stop()


def test_a_path_in_a_frame_tf_does_not_know_is_reported():
    scene = FakeScene()
    layer = PathLayer(
        node=None,  # type: ignore[arg-type]
        server=SimpleNamespace(scene=scene),  # type: ignore[arg-type]
        frame_known=lambda frame: frame == "odom",
    )
    try:
        layer.draw(path_msg([(0.0, 0.0), (1.0, 1.0)]))
        assert "not on TF" in layer.describe() and "2 poses, 1.4 m" in layer.describe()
    finally:
        layer.worker.stop()
