"""The classroom arm in 3D, built from cylinders and spheres, driven by /joint_states.

Geometry comes from ``nodes/common/arm_kinematics.py`` (the same forward
kinematics the arm node uses), so the drawing reaches exactly where the node
says. Nodes are created once, hidden; the arm shows while the followed
JointState names its four joints (another robot's joint states, or none,
draw no phantom arm), and each message only moves it.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Sequence

import numpy as np
import viser
from rclpy.node import Node
from sensor_msgs.msg import JointState

from app.scene import transforms as tf
from app.scene.follow import OneTopicLayer, TopicFollower
from app.scene.frames import BASE_PATH
from app.scene.latest import LatestWorker
from app.scene.topic_picker import NONE
from nodes.common.arm_kinematics import JOINT_NAMES, link_points

ARM_PATH = f"{BASE_PATH}/arm"
MAX_HZ = 30.0
LINK_RADII = (0.035, 0.025, 0.02, 0.012)
LINK_COLOURS = ((90, 90, 100), (240, 140, 20), (240, 140, 20), (60, 60, 60))


def joints_from_message(names: Sequence[str], positions: Sequence[float]) -> np.ndarray | None:
    """The arm's 4 joint angles from a JointState, by name (or by order if names are absent)."""
    by_name = dict(zip(names, positions, strict=False))
    if all(n in by_name for n in JOINT_NAMES):
        return np.array([float(by_name[n]) for n in JOINT_NAMES])
    if not names and len(positions) >= len(JOINT_NAMES):
        return np.array([float(v) for v in positions[: len(JOINT_NAMES)]])
    return None


def segment_poses(
    points: np.ndarray,
) -> list[tuple[tuple[float, float, float], tuple[float, float, float, float], float]]:
    """(centre, wxyz, length) of a cylinder along each consecutive pair of joint points."""
    out = []
    for a, b in zip(points[:-1], points[1:], strict=True):
        out.append((tf.as_xyz((a + b) / 2), tf.quat_z_to(b - a), float(np.linalg.norm(b - a))))
    return out


class ArmLayer(OneTopicLayer):
    def __init__(
        self,
        node: Node,
        server: viser.ViserServer,
        *,
        on_joints: Callable[[Sequence[str], Sequence[float]], None] | None = None,
    ) -> None:
        self._server = server
        self._on_joints = on_joints
        self.joints = np.zeros(len(JOINT_NAMES))
        self._note = ""
        scene = server.scene
        pts = link_points(self.joints)
        self._links = []
        for i, (centre, wxyz, length) in enumerate(segment_poses(pts)):
            self._links.append(
                scene.add_cylinder(
                    f"{ARM_PATH}/link{i}",
                    radius=LINK_RADII[i],
                    height=max(length, 1e-3),
                    color=LINK_COLOURS[i],
                    position=centre,
                    wxyz=wxyz,
                    visible=False,
                )
            )
        self._joints = [
            scene.add_icosphere(
                f"{ARM_PATH}/joint{i}",
                radius=0.03 if i else 0.06,
                color=(40, 40, 40),
                subdivisions=2,
                position=tf.as_xyz(pts[i]),
                visible=False,
            )
            for i in range(len(pts))
        ]
        self._label = scene.add_label(
            f"{ARM_PATH}/label", "arm", position=(0.0, 0.0, 0.16), visible=False
        )
        self._shown = False
        self._show_lock = threading.Lock()  # the drawing thread and select() both show/hide
        worker = LatestWorker("arm", self._draw, MAX_HZ)
        super().__init__(TopicFollower(node, worker, JointState, qos=10))

    def _draw(self, msg: JointState) -> None:
        if self._on_joints is not None and len(msg.position):
            names = list(msg.name) or [f"joint{i}" for i in range(len(msg.position))]
            self._on_joints(names, list(msg.position))
        joints = joints_from_message(list(msg.name), list(msg.position))
        if joints is None:
            self._note = (
                f"⚠️ this JointState names {list(msg.name)}; the arm model needs {list(JOINT_NAMES)}"
            )
            self._show(False)
            return
        self.set_joints(joints)
        self._show(True)

    def _show(self, shown: bool) -> None:
        """Show or hide the whole arm (drawing thread, or the UI thread once nothing draws)."""
        with self._show_lock:
            if shown == self._shown:
                return
            self._shown = shown
            with self._server.atomic():
                for handle in (*self._links, *self._joints, self._label):
                    handle.visible = shown

    def select(self, topic: str) -> None:
        super().select(topic)
        if topic == NONE:
            self._show(False)

    def set_joints(self, joints: np.ndarray) -> None:
        pts = link_points(joints)
        with self._server.atomic():
            for link, (centre, wxyz, _length) in zip(self._links, segment_poses(pts), strict=True):
                link.position = centre
                link.wxyz = wxyz
            for joint, p in zip(self._joints, pts, strict=True):
                joint.position = tf.as_xyz(p)
        self.joints = np.asarray(joints, dtype=float)
        tip = pts[-1]
        angles = ", ".join(
            f"{n} {math.degrees(q):+.0f}°" for n, q in zip(JOINT_NAMES, joints, strict=True)
        )
        self._note = f"{angles} · gripper at ({tip[0]:.2f}, {tip[1]:.2f}, {tip[2]:.2f}) m"

    def describe(self) -> str:
        return self._note if self.topic != NONE else ""
