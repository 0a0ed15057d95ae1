"""The unit-13 arm as a ROS robot: robotic_arm + robot_state_publisher with its URDF.

Both run as catalog nodes under the supervisor (the ``arm_tf`` group); the
transforms on ``/tf`` chained from base_link to tool0 must put the fingertip
where robotic_arm's own ``/end_effector_pose`` says it is.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped
from rclpy.qos import DurabilityPolicy, QoSProfile
from scipy.spatial.transform import Rotation
from tf2_msgs.msg import TFMessage

from app.catalog import lookup_group
from tests.conftest import wait_until

pytestmark = pytest.mark.ros

CHAIN = ("turret", "upper_arm", "forearm", "gripper", "tool0")


def _matrix(t) -> np.ndarray:
    m = np.eye(4)
    r = t.transform.rotation
    m[:3, :3] = Rotation.from_quat([r.x, r.y, r.z, r.w]).as_matrix()
    v = t.transform.translation
    m[:3, 3] = (v.x, v.y, v.z)
    return m


def test_arm_joints_become_tf_that_agree_with_its_pose(supervisor, probe) -> None:
    lock = threading.Lock()
    latest: dict[str, object] = {}
    poses: list[PoseStamped] = []

    def on_tf(msg: TFMessage) -> None:
        with lock:
            for t in msg.transforms:
                latest[t.child_frame_id] = t

    def on_pose(msg: PoseStamped) -> None:
        with lock:
            poses.append(msg)

    # As tf2_ros's listener: /tf_static's several latched writers (the camera's static
    # transform, the arm's robot_state_publisher) each send a sample to a late joiner at
    # once, and a queue of one would keep only the newest.
    static = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    probe.node.create_subscription(TFMessage, "/tf", on_tf, 100)
    probe.node.create_subscription(TFMessage, "/tf_static", on_tf, static)
    probe.node.create_subscription(PoseStamped, "/end_effector_pose", on_pose, 10)
    for member in lookup_group("arm_tf").members:
        supervisor.start(member)
    wait_until(lambda: all(f in latest for f in CHAIN) and poses, 30, what="the arm's frames")
    # The arm stands still at HOME: its latest pose and latest transforms describe one state.
    with lock:
        chain = np.eye(4)
        for frame in CHAIN:
            t = latest[frame]
            assert t.header.frame_id == {"turret": "base_link"}.get(frame, t.header.frame_id)
            chain = chain @ _matrix(t)
        pose = poses[-1].pose
    assert np.allclose(chain[:3, 3], [pose.position.x, pose.position.y, pose.position.z], atol=1e-6)
    q = pose.orientation
    expected = Rotation.from_quat([q.x, q.y, q.z, q.w]).as_matrix()
    assert np.allclose(chain[:3, :3], expected, atol=1e-6)
