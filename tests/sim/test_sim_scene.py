"""The 3D view's pieces for the simulated world, without ROS or a browser: pure functions."""

from __future__ import annotations

import html
import json
import math

import numpy as np
import pytest
from geometry_msgs.msg import Point
from visualization_msgs.msg import Marker

from app.ros.graph import GraphSnapshot, TopicInfo
from app.scene import marker_plan as mp
from app.scene.drive import BUTTONS, KEYS, follow_step, key_listener, overview
from app.scene.laser_scan import range_colours, scan_points
from app.scene.namespaced_robots import namespaced_descriptions, tag_of
from app.scene.sim_world import marker_bounds, tf_frame_path
from app.scene.tf_camera import DEFAULT_FOV, frustum_shape, info_topic_for


def test_a_scan_becomes_points_only_where_a_ray_hit_something():
    ranges = [1.0, math.inf, -math.inf, math.nan, 0.05, 9.0, 2.0, 0.0]
    points, hit = scan_points(ranges, 0.0, math.pi / 2, 0.1, 8.0)
    assert hit.tolist() == [1.0, 2.0]  # no return, too close, past range_max: nothing
    assert points.dtype == np.float32
    assert np.allclose(points, [[1.0, 0.0, 0.0], [-2.0, 0.0, 0.0]], atol=1e-6)
    colours = range_colours(np.array([0.0, 8.0]), 8.0)
    assert colours.dtype == np.uint8 and colours[0].tolist() != colours[1].tolist()


def test_the_frustum_opens_as_the_camera_info_says():
    focal = 120.0 / math.tan(math.radians(30.0))  # 320x240 with a 60 degree vertical view
    k = [focal, 0.0, 160.0, 0.0, focal, 120.0, 0.0, 0.0, 1.0]
    fov, aspect = frustum_shape(k, 320, 240)
    assert math.degrees(fov) == pytest.approx(60.0) and aspect == pytest.approx(4 / 3)
    assert frustum_shape(None, 640, 480) == (DEFAULT_FOV, pytest.approx(4 / 3))
    assert frustum_shape([0.0] * 9, 640, 480)[0] == DEFAULT_FOV  # an unset K: the default
    assert info_topic_for("/camera/image_raw") == "/camera/camera_info"
    assert info_topic_for("/robot1/camera/image_raw") == "/robot1/camera/camera_info"


def test_following_keeps_each_cameras_angle_and_moves_it_with_the_robot():
    camera = (np.array([-2.0, -3.0, 2.0]), np.array([0.0, 0.0, 0.0]))
    robot = np.array([0.5, 0.0, 0.0])
    (first,) = follow_step([camera], robot, None) or []
    assert first[1] == pytest.approx(robot)  # looks at the robot
    assert first[0] - first[1] == pytest.approx(camera[0] - camera[1])  # same angle, distance
    assert follow_step([first], robot + 0.005, robot) is None  # a twitch: leave it be
    (moved,) = follow_step([first], robot + [0.3, 0.1, 0.0], robot) or []
    assert moved[0] - first[0] == pytest.approx([0.3, 0.1, 0.0])
    assert moved[1] - first[1] == pytest.approx([0.3, 0.1, 0.0])


def test_the_overview_looks_down_on_the_whole_room_from_a_corner():
    position, look_at = overview(np.array([-2.5, -2.5, -0.01]), np.array([2.5, 2.5, 0.5]))
    assert look_at[2] == pytest.approx(-0.01)  # the floor's middle
    assert np.linalg.norm(look_at[:2]) < 2.0
    back = position - look_at
    assert back[2] > 2.0 and back[0] < 0 and back[1] < 0  # above, from the south-west
    assert 4.0 < np.linalg.norm(back) < 8.0


def test_a_building_is_seen_from_higher_up_than_a_room():
    room = overview(np.array([-2.5, -2.5, 0.0]), np.array([2.5, 2.5, 0.5]))
    office = overview(np.array([-1.0, -4.0, 0.0]), np.array([9.0, 4.0, 1.0]))

    def pitch(view: tuple[np.ndarray, np.ndarray]) -> float:  # degrees below the horizon
        back = view[0] - view[1]
        return math.degrees(math.atan2(back[2], float(np.linalg.norm(back[:2]))))

    assert pitch(room) < 45.0 < pitch(office)  # the office's rooms show over their walls
    back = office[0] - office[1]
    assert back[1] < 0 and 8.0 < np.linalg.norm(back) < 14.0  # from the south, all of it


def test_only_namespaced_descriptions_with_a_publisher_are_followed():
    topics = (
        TopicInfo("/robot_description", ("std_msgs/msg/String",), 1, 1),
        TopicInfo("/arm/robot_description", ("std_msgs/msg/String",), 1, 1),
        TopicInfo("/old/robot_description", ("std_msgs/msg/String",), 0, 1),
        TopicInfo("/odd/robot_description", ("std_msgs/msg/Int32",), 1, 0),
    )
    assert namespaced_descriptions(GraphSnapshot(topics=topics)) == ["/arm/robot_description"]
    assert tag_of("/arm/robot_description") == "arm"
    assert tag_of("/team-2/arm/robot_description") == "team_2_arm"


def _marker(kind: int, x: float, size: float, action: int = Marker.ADD) -> Marker:
    marker = Marker(type=kind, action=action)
    marker.pose.position.x = x
    marker.scale.x = marker.scale.y = marker.scale.z = size
    return marker


def test_the_world_box_spans_its_markers_sizes():
    low, high = marker_bounds(
        [Marker(action=Marker.DELETEALL), _marker(1, -2.0, 1.0), _marker(2, 3.0, 2.0)]
    ) or (None, None)
    assert low.tolist() == [-2.5, -1.0, -1.0] and high.tolist() == [4.0, 1.0, 1.0]
    assert marker_bounds([Marker(action=Marker.DELETEALL)]) is None
    assert tf_frame_path("world") == "/tf_view/frames/world"
    assert tf_frame_path("/a/b") == "/tf_view/frames/a__b"


def test_a_triangle_list_marker_becomes_a_mesh():
    marker = _marker(Marker.TRIANGLE_LIST, 0.0, 2.0)
    corners = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 0, 0), (0, 1, 0), (9, 9, 9)]
    marker.points = [Point(x=float(x), y=float(y), z=float(z)) for x, y, z in corners]
    plan = mp.plan_marker(marker)
    assert plan.shape is not None and plan.shape.kind == "mesh"
    args = plan.shape.args
    assert args["kind"] == "mesh"
    assert args["vertices"].shape == (6, 3) and args["vertices"][1].tolist() == [2.0, 0.0, 0.0]
    assert args["faces"].tolist() == [[0, 1, 2], [3, 4, 5]]  # the 7th point: no triangle
    marker.points = marker.points[:2]
    assert "fewer than 3 points" in mp.plan_marker(marker).skipped


def test_the_key_listener_presses_only_the_four_drive_buttons():
    page = html.unescape(key_listener())
    assert set(KEYS.values()) == set(BUTTONS)
    assert f"const keys = {json.dumps(KEYS)};" in page  # arrow keys -> the buttons' labels
    assert "fetch(" not in page and "classroom/act" not in page  # clicks buttons, no links
    assert set(BUTTONS.values()) == {"up", "down", "left", "right"}  # the teleop's key names
