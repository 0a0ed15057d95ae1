"""Perception and manipulation chains as real processes, observed from a probe node."""

from __future__ import annotations

import numpy as np
import pytest
from geometry_msgs.msg import PointStamped, PoseStamped
from sensor_msgs.msg import Image, JointState, PointCloud2
from std_msgs.msg import String
from tutorial_interfaces.msg import DetectedObject
from visualization_msgs.msg import Marker, MarkerArray

from app.ros.monitor import TopicMonitor
from nodes.common.arm_kinematics import forward_kinematics
from nodes.common.image_conversion import image_to_array
from nodes.common.pointcloud import pointcloud2_to_xyz_rgb
from tests.conftest import wait_until

pytestmark = pytest.mark.ros


def _stamp(msg) -> tuple[int, int]:
    return msg.header.stamp.sec, msg.header.stamp.nanosec


def _xyz(point) -> np.ndarray:
    return np.array([point.x, point.y, point.z])


def test_camera_to_arm_chain_reaches_the_target(supervisor, probe):
    taps = {
        "cam": TopicMonitor(probe.node, "/pos_in_cam_frame", PointStamped, keep=100, qos=10),
        "base": TopicMonitor(
            probe.node, "/pos_in_robot_base_frame", PointStamped, keep=100, qos=10
        ),
        "joints": TopicMonitor(probe.node, "/joint_states", JointState, keep=5, qos=10),
        "pose": TopicMonitor(probe.node, "/end_effector_pose", PoseStamped, keep=5, qos=10),
        "status": TopicMonitor(probe.node, "/arm_status", String, keep=50, qos=10),
    }
    supervisor.start("robotic_arm")
    supervisor.start("coordinate_transform")
    # A new random target every 8 s: enough time to get there even on a busy machine.
    supervisor.start("camera_publisher", ["-p", "period:=8.0", "-p", "seed:=4"])

    def matched_pairs():
        cam_by_stamp = {_stamp(m): _xyz(m.point) for _, m in taps["cam"].recent()}
        pairs = [
            (cam_by_stamp[_stamp(m)], _xyz(m.point), m.header.frame_id)
            for _, m in taps["base"].recent()
            if _stamp(m) in cam_by_stamp
        ]
        return len(pairs) >= 3 and pairs

    pairs = wait_until(matched_pairs, timeout=60, what="camera and base points with one stamp")
    # The transform, checked by hand for the default mount (0.25, 0, 0.7), looking down:
    # x_base = 0.25 + x_cam, y_base = -y_cam, z_base = 0.7 - z_cam.
    for cam, base, frame in pairs:
        assert frame == "base_link"
        expected = np.array([0.25 + cam[0], -cam[1], 0.70 - cam[2]])
        np.testing.assert_allclose(base, expected, atol=1e-9)

    def arm_on_target():
        _, target = taps["base"].recent(1)[0]
        joints = taps["joints"].recent(1)
        if not joints:
            return False
        tip = forward_kinematics(joints[0][1].position).position
        return np.linalg.norm(tip - _xyz(target.point)) < 0.005 and (target, joints[0][1])

    target, joint_state = wait_until(arm_on_target, timeout=60, what="the gripper on the target")
    assert list(joint_state.name) == ["base_yaw", "shoulder_pitch", "elbow_pitch", "wrist_pitch"]
    wait_until(
        lambda: any(m.data.startswith("reached") for _, m in taps["status"].recent()),
        timeout=30,
        what='"reached" on /arm_status',
    )

    # The published end-effector pose is the forward kinematics of the joint states
    # (both carry the stamp of the same control step).
    def pose_and_joints():
        joints = {_stamp(m): m for _, m in taps["joints"].recent()}
        return next(
            ((p, joints[_stamp(p)]) for _, p in taps["pose"].recent() if _stamp(p) in joints),
            None,
        )

    pose, joints = wait_until(pose_and_joints, timeout=10, what="a pose and joints of one step")
    assert pose.header.frame_id == "base_link"
    expected = forward_kinematics(joints.position).position
    np.testing.assert_allclose(_xyz(pose.pose.position), expected, atol=1e-6)

    # A target out of reach is reported, not ignored.
    publisher = probe.node.create_publisher(PointStamped, "/pos_in_robot_base_frame", 10)
    far = PointStamped()
    far.header.frame_id = "base_link"
    far.point.x, far.point.y, far.point.z = 1.5, 0.0, 0.3

    def reported_unreachable():
        publisher.publish(far)
        return any("unreachable" in m.data for _, m in taps["status"].recent())

    wait_until(reported_unreachable, timeout=30, interval=0.5, what="the unreachable report")
    # The warning is logged before the status is published, but it reaches us through the
    # supervisor's reader of the arm's pipe, which a loaded machine may run later than DDS
    # delivers the status (CI of 2026-12-04).
    wait_until(
        lambda: any("unreachable" in line for line in supervisor.output("robotic_arm")),
        timeout=10,
        what="the arm's warning for the unreachable target in its output",
    )


def test_image_pipeline_finds_the_ball(supervisor, probe):
    objects = TopicMonitor(probe.node, "/object_detection/object", DetectedObject, keep=20, qos=10)
    annotated = TopicMonitor(probe.node, "/object_detection/output", Image, keep=2, qos=10)
    supervisor.start("object_detector")
    supervisor.start("image_publisher", ["-p", "fps:=10.0"])
    wait_until(lambda: objects.count >= 3, timeout=60, what="detections of the red ball")
    _, found = objects.recent(1)[0]
    assert found.label == "red_ball"
    assert 30 < found.radius_px < 40  # drawn with a 34 px radius
    # A 4 cm ball 34-35 px wide through a 525 px lens is about 0.6 m away.
    assert 0.5 < found.position_in_camera.z < 0.7
    wait_until(lambda: annotated.count >= 1, timeout=30, what="an annotated image")
    _, image = annotated.recent(1)[0]
    assert (image.width, image.height, image.encoding) == (640, 480, "bgr8")
    assert image_to_array(image).shape == (480, 640, 3)


def test_video_to_slam_chain_builds_a_growing_map(supervisor, probe):
    clouds = TopicMonitor(probe.node, "/cam/map_points", PointCloud2, keep=3, qos=10)
    markers = TopicMonitor(probe.node, "/cam/camera_pose", MarkerArray, keep=2, qos=10)
    features = TopicMonitor(probe.node, "/cam/feature_ext_viz", Image, keep=2, qos=10)
    supervisor.start("slam_node")
    supervisor.start("video_publisher", ["-p", "fps:=10.0"])

    def cloud_size():
        recent = clouds.recent(1)
        return recent[0][1].width if recent else 0

    first = wait_until(lambda: cloud_size() >= 100, timeout=90, what="a first map of 100 points")
    grown = wait_until(
        lambda: cloud_size() >= first + 300 and cloud_size(),
        timeout=90,
        what="the map to grow by 300 points",
    )
    _, cloud = clouds.recent(1)[0]
    assert cloud.header.frame_id == "map"
    xyz, rgb = pointcloud2_to_xyz_rgb(cloud)
    assert xyz.shape == (grown, 3) and xyz.dtype == np.float32
    assert np.isfinite(xyz).all()
    assert rgb is not None and rgb.shape == (grown, 3)

    def trajectory():
        recent = markers.recent(1)
        if not recent:
            return None
        strips = [m for m in recent[0][1].markers if m.type == Marker.LINE_STRIP]
        return strips and len(strips[0].points) >= 30 and strips[0]

    path = wait_until(trajectory, timeout=60, what="a trajectory of 30 camera poses")
    assert path.header.frame_id == "map"
    positions = np.array([[p.x, p.y, p.z] for p in path.points])
    assert np.isfinite(positions).all()
    assert np.linalg.norm(np.diff(positions, axis=0), axis=1).sum() > 0  # the camera moved

    wait_until(lambda: features.count >= 1, timeout=30, what="the feature image")
    _, image = features.recent(1)[0]
    assert (image.width, image.height, image.encoding) == (640, 480, "bgr8")
