"""2D Pose Estimate and Nav2 Goal: the click's ray on the floor, and the pose sent (no DDS)."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from app.scene.pose_tools import (
    ESTIMATE,
    PoseTools,
    floor_point,
    goal_command,
    heading,
    initial_pose,
    initial_pose_command,
    navigation_goal,
)


def turned(yaw: float, at=(0.0, 0.0, 0.0)) -> np.ndarray:
    pose = np.eye(4)
    c, s = math.cos(yaw), math.sin(yaw)
    pose[:2, :2] = [[c, -s], [s, c]]
    pose[:3, 3] = at
    return pose


def test_a_ray_from_above_meets_the_floor_where_it_points():
    assert floor_point((1.0, 2.0, 3.0), (0.0, 0.0, -1.0)) == pytest.approx((1.0, 2.0))
    assert floor_point((0.0, 0.0, 2.0), (1.0, 0.0, -1.0)) == pytest.approx((2.0, 0.0))
    # the floor of a frame moved and turned in the view: the point in that frame's x, y
    frame = turned(math.pi / 2, at=(5.0, 0.0, 1.0))
    assert floor_point((5.0, 3.0, 4.0), (0.0, 0.0, -2.0), frame) == pytest.approx((3.0, 0.0))


def test_a_ray_along_the_floor_or_away_from_it_misses():
    assert floor_point((0.0, 0.0, 1.0), (1.0, 0.0, 0.0)) is None  # parallel to the floor
    assert floor_point((0.0, 0.0, 1.0), (0.3, 0.0, 0.5)) is None  # pointing up, at the sky
    assert floor_point((0.0, 0.0, -1.0), (0.0, 0.0, -1.0)) is None  # under it, looking down
    assert floor_point((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)) is None
    assert floor_point((0.0, 0.0, float("nan")), (0.0, 0.0, -1.0)) is None


def test_the_heading_runs_from_the_first_click_to_the_second():
    assert heading((0.0, 0.0), (1.0, 1.0)) == pytest.approx(math.pi / 4)
    assert heading((1.0, 0.0), (0.0, 0.0)) == pytest.approx(math.pi)
    assert heading((1.0, 1.0), (1.0, 1.0)) == 0.0  # one spot clicked twice: facing +x


def test_the_initial_pose_carries_rvizs_covariance_and_the_heading_as_a_quaternion():
    msg = initial_pose(1.5, -0.5, math.pi / 2)
    assert msg.header.frame_id == "map"
    assert (msg.pose.pose.position.x, msg.pose.pose.position.y) == (1.5, -0.5)
    q = msg.pose.pose.orientation
    assert (q.x, q.y, q.z, q.w) == pytest.approx((0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5)))
    covariance = list(msg.pose.covariance)
    assert covariance[0] == covariance[7] == 0.25
    assert covariance[35] == pytest.approx(0.0685, abs=1e-4)
    assert sum(covariance) == pytest.approx(0.25 + 0.25 + (math.pi / 12) ** 2)
    assert "ros2 topic pub --once /initialpose geometry_msgs/msg/PoseWithCovarianceStamped" in (
        initial_pose_command(1.5, -0.5, math.pi / 2)
    )


def test_the_goal_is_a_navigate_to_pose_in_map():
    goal = navigation_goal(2.0, 1.0, math.pi)
    assert goal.pose.header.frame_id == "map" and goal.pose.pose.position.x == 2.0
    assert goal.pose.pose.orientation.z == pytest.approx(1.0)
    assert goal_command(2.0, 1.0, math.pi).startswith(
        "ros2 action send_goal /navigate_to_pose nav2_msgs/action/NavigateToPose '{pose:"
    )


class FakeGui:
    def add_markdown(self, content: str, **_kw: Any) -> Any:
        return SimpleNamespace(content=content)

    def add_button_group(self, *_a: Any, **_kw: Any) -> Any:
        return SimpleNamespace(on_click=lambda _f: None)


class FakeScene:
    def __init__(self) -> None:
        self.listeners: list[Any] = []
        self.nodes: dict[str, Any] = {}

    def on_click(self) -> Any:
        return self.listeners.append

    def remove_click_callback(self, func: Any) -> None:
        self.listeners.remove(func)

    def _add(self, name: str, *_a: Any, **_kw: Any) -> Any:
        self.nodes[name] = SimpleNamespace(remove=lambda: self.nodes.pop(name, None))
        return self.nodes[name]

    add_icosphere = add_line_segments = _add


class FakeNode:
    def __init__(self) -> None:
        self.published: list[Any] = []

    def create_publisher(self, _type: Any, topic: str, _qos: Any) -> Any:
        return SimpleNamespace(topic=topic, publish=self.published.append)

    def destroy_publisher(self, _publisher: Any) -> None:
        pass

    def get_clock(self) -> Any:
        return SimpleNamespace(now=lambda: SimpleNamespace(to_msg=lambda: None))


def test_two_clicks_publish_the_estimate_and_a_missed_click_only_says_so():
    scene, node = FakeScene(), FakeNode()
    map_pose = turned(0.0, at=(1.0, 0.0, 0.0))  # map sits 1 m along the view's x
    tools = PoseTools(
        FakeGui(),  # type: ignore[arg-type]
        SimpleNamespace(post=lambda f: f()),  # type: ignore[arg-type]
        node,  # type: ignore[arg-type]
        SimpleNamespace(scene=scene),  # type: ignore[arg-type]
        lambda frame: map_pose if frame == "map" else None,
    )
    tools.clicked((0.0, 0.0, 5.0), (0.0, 0.0, -1.0))  # not armed: ignored
    assert not node.published and not scene.listeners
    tools.press(ESTIMATE)
    assert len(scene.listeners) == 1  # the browsers' clicks are asked for now
    tools.clicked((0.0, 0.0, 5.0), (0.0, 0.0, 1.0))  # at the sky
    assert "missed the floor" in tools.note.content and tools.first is None
    tools.clicked((3.0, 2.0, 5.0), (0.0, 0.0, -1.0))
    assert tools.first == pytest.approx((2.0, 2.0)) and not node.published
    tools.clicked((3.0, 4.0, 5.0), (0.0, 0.0, -1.0))  # towards +y of map
    (msg,) = node.published
    assert msg.header.frame_id == "map"
    assert (msg.pose.pose.position.x, msg.pose.pose.position.y) == pytest.approx((2.0, 2.0))
    assert msg.pose.pose.orientation.z == pytest.approx(math.sin(math.pi / 4))
    assert not scene.listeners and tools.tool is None  # done: clicks are the view's again
    assert "ros2 topic pub --once /initialpose" in tools.note.content
    tools.close()
