"""Frames, quaternions, markers and the topic picker of the 3D view, without ROS or a browser."""

from __future__ import annotations

import math

import numpy as np
import pytest
from geometry_msgs.msg import Point
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker

from app.ros.graph import GraphSnapshot, TopicInfo
from app.scene import marker_plan as mp
from app.scene import topic_picker as picker
from app.scene import transforms as tf
from app.scene.arm import joints_from_message, segment_poses
from app.scene.camera_params import pose_parameters
from app.scene.frames import BASE_PATH, CAMERA_PATH, CameraPose, scene_path_for_frame
from nodes.common.arm_kinematics import link_points
from nodes.common.frames import pose_to_matrix, rpy_to_matrix
from nodes.coordinate_transform import DEFAULT_CAMERA_POSE


def test_ros_and_viser_quaternion_orders():
    # 90 degrees about z: ROS (x, y, z, w) = (0, 0, s, s)
    s = math.sqrt(0.5)
    assert tf.ros_to_wxyz(0, 0, s, s) == pytest.approx((s, 0, 0, s))
    assert tf.wxyz_to_ros((s, 0, 0, s)) == pytest.approx((0, 0, s, s))
    assert tf.ros_to_wxyz(0, 0, 0, 0) == (1.0, 0.0, 0.0, 0.0)  # unset orientation


@pytest.mark.parametrize("rpy", [(0.1, -0.4, 2.0), (math.pi, 0, 0), (-2.3, 0.2, -1.5)])
def test_rpy_matches_the_nodes_convention(rpy):
    np.testing.assert_allclose(
        tf.quat_to_matrix(tf.rpy_to_quat(*rpy)), rpy_to_matrix(*rpy), atol=1e-12
    )
    back = tf.quat_to_rpy(tf.rpy_to_quat(*rpy))
    np.testing.assert_allclose(rpy_to_matrix(*back), rpy_to_matrix(*rpy), atol=1e-9)


def test_matrix_quaternion_round_trip_near_180_degrees():
    rot = rpy_to_matrix(math.pi - 1e-9, 0.0, 0.0)
    np.testing.assert_allclose(tf.quat_to_matrix(tf.matrix_to_quat(rot)), rot, atol=1e-7)


def test_camera_pose_is_the_coordinate_transform_nodes_matrix():
    pose = CameraPose()
    expected = pose_to_matrix(*(DEFAULT_CAMERA_POSE[k] for k in DEFAULT_CAMERA_POSE))
    np.testing.assert_allclose(pose.matrix(), expected, atol=1e-12)
    # a point 0.62 m in front of the lens lands below the camera, near the table
    p_base = tf.apply(pose.matrix(), [[0.0, 0.0, 0.62]])[0]
    np.testing.assert_allclose(p_base, [0.25, 0.0, 0.08], atol=1e-9)


def test_pose_parameters_use_the_nodes_names_as_doubles():
    params = pose_parameters(CameraPose(1, 2, 3, 0.1, 0.2, 0.3))
    assert {p.name for p in params} == set(DEFAULT_CAMERA_POSE)
    assert {p.name: p.value.double_value for p in params}["camera_z"] == 3.0


def test_frame_ids_map_to_scene_nodes():
    assert scene_path_for_frame("camera") == (CAMERA_PATH, True)
    assert scene_path_for_frame("/base_link") == (BASE_PATH, True)
    assert scene_path_for_frame("map") == (BASE_PATH, True)
    assert scene_path_for_frame("", "/pos_in_cam_frame") == (CAMERA_PATH, True)
    assert scene_path_for_frame("lidar_top") == (BASE_PATH, False)


def test_arm_cylinders_follow_the_kinematics():
    joints = np.array([0.3, 0.8, -1.2, -0.5])
    pts = link_points(joints)
    for (centre, wxyz, length), a, b in zip(segment_poses(pts), pts[:-1], pts[1:], strict=True):
        np.testing.assert_allclose(centre, (a + b) / 2)
        axis = tf.quat_to_matrix(wxyz) @ [0, 0, 1]
        np.testing.assert_allclose(axis * length, b - a, atol=1e-9)


def test_joint_states_are_read_by_name():
    names = ["wrist_pitch", "base_yaw", "elbow_pitch", "shoulder_pitch", "gripper"]
    q = joints_from_message(names, [4.0, 1.0, 3.0, 2.0, 9.0])
    np.testing.assert_array_equal(q, [1.0, 2.0, 3.0, 4.0])
    assert joints_from_message(["a", "b"], [1.0, 2.0]) is None


def _marker(kind: int, action: int = mp.ADD, **kw) -> Marker:
    m = Marker()
    m.header.frame_id = "map"
    m.ns, m.id, m.type, m.action = "t", 7, kind, action
    m.scale.x, m.scale.y, m.scale.z = 0.2, 0.1, 0.3
    m.color = ColorRGBA(r=1.0, g=0.5, b=0.0, a=1.0)
    m.pose.orientation.w = 1.0
    for k, v in kw.items():
        setattr(m, k, v)
    return m


def test_each_marker_type_becomes_a_primitive():
    kinds = {
        mp.SPHERE: "sphere",
        mp.CUBE: "box",
        mp.CYLINDER: "cylinder",
        mp.ARROW: "arrows",
        mp.TEXT_VIEW_FACING: "text",
    }
    for t, kind in kinds.items():
        shape = mp.plan_marker(_marker(t, text="hi")).shape
        assert shape is not None and shape.kind == kind and shape.color == (255, 128, 0)
    sphere = mp.plan_marker(_marker(mp.SPHERE)).shape
    assert sphere.args["scale"] == pytest.approx((0.2, 0.1, 0.3))  # diameters with radius 0.5
    pts = [Point(x=float(i), y=0.0, z=0.0) for i in range(4)]
    strip = mp.plan_marker(_marker(mp.LINE_STRIP, points=pts)).shape
    assert strip.kind == "lines" and strip.args["points"].shape == (3, 2, 3)
    lst = mp.plan_marker(_marker(mp.LINE_LIST, points=pts)).shape
    assert lst.args["points"].shape == (2, 2, 3)
    dots = mp.plan_marker(_marker(mp.POINTS, points=pts)).shape
    assert dots.kind == "points" and dots.args["colors"].shape == (4, 3)


def test_arrow_from_pose_points_along_x_with_its_length():
    shape = mp.plan_marker(_marker(mp.ARROW)).shape
    np.testing.assert_allclose(shape.args["points"], [[[0, 0, 0], [0.2, 0, 0]]])


def test_delete_and_deleteall():
    assert mp.plan_marker(_marker(mp.SPHERE, action=mp.DELETE)).delete == ("t", 7)
    assert mp.plan_marker(_marker(mp.SPHERE, action=mp.DELETEALL)).delete_all
    assert mp.plan_marker(_marker(mp.MESH_RESOURCE)).skipped


def test_picker_offers_only_drawable_topics_and_explains_silence():
    graph = GraphSnapshot(
        topics=(
            TopicInfo("/chatter", ("std_msgs/msg/String",), 1, 0),
            TopicInfo("/cloud", ("sensor_msgs/msg/PointCloud2",), 1, 1),
            TopicInfo("/old_cloud", ("sensor_msgs/msg/PointCloud2",), 0, 1),
        )
    )
    assert picker.options(graph, picker.CLOUD_TYPES, picker.NONE) == [
        picker.NONE,
        "/cloud",
        "/old_cloud",
    ]
    assert "/gone" in picker.options(graph, picker.CLOUD_TYPES, "/gone")  # keep the pick
    assert "no publisher" in picker.liveness_note(graph, "/old_cloud", 0, None)
    assert "no publisher any more" in picker.liveness_note(graph, "/old_cloud", 5, 1.0)
    assert "waiting" in picker.liveness_note(graph, "/cloud", 0, None)
    assert "stopped publishing" in picker.liveness_note(graph, "/cloud", 5, 10.0)
    assert picker.liveness_note(graph, "/cloud", 5, 0.1) == ""
    assert picker.liveness_note(graph, "/cloud", 1, 60.0, latched=True) == ""  # a map, say


def test_the_desk_shows_only_while_another_node_feeds_it():
    def graph(*topics: TopicInfo) -> GraphSnapshot:
        return GraphSnapshot(topics=topics)

    assert not picker.desk_in_use(None)
    assert not picker.desk_in_use(graph(TopicInfo("/chatter", ("std_msgs/msg/String",), 1, 0)))
    joints = TopicInfo("/joint_states", ("sensor_msgs/msg/JointState",), 1, 1)
    assert picker.desk_in_use(graph(joints))
    point = TopicInfo("/pos_in_cam_frame", ("geometry_msgs/msg/PointStamped",), 1, 0)
    assert picker.desk_in_use(graph(point))
    # The dashboard's own publisher (a learner's Publish form) feeds nothing of the desk's.
    own = TopicInfo("/pose", ("geometry_msgs/msg/PoseStamped",), 1, 0, own_publishers=1)
    assert not picker.desk_in_use(graph(own))
    # A topic only subscribed to (nobody publishes it) does not either.
    assert not picker.desk_in_use(graph(TopicInfo("/joint_states", JOINTS_TYPE, 0, 2)))


JOINTS_TYPE = ("sensor_msgs/msg/JointState",)
