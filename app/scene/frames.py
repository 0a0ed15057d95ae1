"""Coordinate frames in the scene: base_link, the camera (axes, label, frustum) and its pose.

The camera<->base transform is one :class:`CameraPose` the learner edits with
sliders or a gizmo in the 3D view. Anything stamped with a frame id is drawn
under that frame's scene node, so viser composes the transforms for us, as
tf does for rviz.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import viser

from app.scene import transforms as tf
from nodes.coordinate_transform import DEFAULT_CAMERA_POSE

BASE_PATH = "/base_link"
CAMERA_PATH = "/base_link/camera"

# frame ids that mean "the robot base / the world" or "the camera"; the
# tutorials use several spellings.
BASE_FRAME_IDS = frozenset({"", "world", "map", "odom", "base", "base_link", "base_footprint"})
CAMERA_FRAME_IDS = frozenset(
    {
        "camera",
        "cam",
        "camera_link",
        "camera_frame",
        "camera_optical_frame",
        "camera_color_optical_frame",
        "camera_depth_optical_frame",
    }
)


def scene_path_for_frame(frame_id: str, topic: str = "") -> tuple[str, bool]:
    """(scene node path, known?) for a header.frame_id; topic names break ties for ''."""
    fid = frame_id.strip().lstrip("/")
    if fid in CAMERA_FRAME_IDS or (not fid and "cam" in topic.split("/")[-1]):
        return CAMERA_PATH, True
    if fid in BASE_FRAME_IDS:
        return BASE_PATH, True
    return BASE_PATH, False


# The coordinate_transform node's own defaults, so the 3D view starts where the node does.
_NODE_DEFAULT = DEFAULT_CAMERA_POSE


@dataclass(frozen=True)
class CameraPose:
    """Pose of the camera (optical) frame in base_link: metres, and fixed-axis RPY in radians."""

    x: float = _NODE_DEFAULT["camera_x"]
    y: float = _NODE_DEFAULT["camera_y"]
    z: float = _NODE_DEFAULT["camera_z"]
    roll: float = _NODE_DEFAULT["camera_roll"]
    pitch: float = _NODE_DEFAULT["camera_pitch"]
    yaw: float = _NODE_DEFAULT["camera_yaw"]

    @property
    def wxyz(self) -> tuple[float, float, float, float]:
        return tf.rpy_to_quat(self.roll, self.pitch, self.yaw)

    @property
    def position(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.z)

    def matrix(self) -> np.ndarray:
        """T_base_camera: p_base = T @ p_camera."""
        return tf.make_matrix(self.wxyz, self.position)

    @classmethod
    def from_wxyz_position(cls, wxyz: tf.Vector, position: tf.Vector) -> CameraPose:
        roll, pitch, yaw = tf.quat_to_rpy(wxyz)
        x, y, z = (float(v) for v in position)
        return cls(x, y, z, roll, pitch, yaw)


class FrameTree:
    """Owns the base and camera frame nodes, the frustum and the pose gizmo."""

    def __init__(self, scene: viser.SceneApi, pose: CameraPose | None = None) -> None:
        self._scene = scene
        self._lock = threading.Lock()
        self._pose = pose or CameraPose()
        self._listeners: list[Callable[[CameraPose, str], None]] = []
        self.base = scene.add_frame(BASE_PATH, axes_length=0.2, axes_radius=0.008)
        self.base_label = scene.add_label(
            f"{BASE_PATH}/label", "base_link", position=(0.0, 0.0, -0.05)
        )
        self.camera = scene.add_frame(
            CAMERA_PATH,
            axes_length=0.12,
            axes_radius=0.006,
            wxyz=self._pose.wxyz,
            position=self._pose.position,
        )
        self.camera_label = scene.add_label(
            f"{CAMERA_PATH}/label", "camera", position=(0.0, -0.06, 0.0)
        )
        self.frustum = scene.add_camera_frustum(
            f"{CAMERA_PATH}/frustum",
            fov=1.0,
            aspect=4 / 3,
            scale=0.1,
            thickness=0.004,
            color=(40, 90, 200),
        )
        self.gizmo = scene.add_transform_controls(
            "/camera_pose_gizmo",
            scale=0.25,
            wxyz=self._pose.wxyz,
            position=self._pose.position,
            visible=False,
        )
        self.gizmo.on_update(self._on_gizmo)

    @property
    def pose(self) -> CameraPose:
        with self._lock:
            return self._pose

    def on_change(self, listener: Callable[[CameraPose, str], None]) -> None:
        """``listener(pose, source)`` runs after every edit; source is "gizmo" or "sliders"."""
        self._listeners.append(listener)

    def set_pose(self, pose: CameraPose, source: str) -> None:
        with self._lock:
            if pose == self._pose:
                return
            self._pose = pose
        self.camera.wxyz = pose.wxyz
        self.camera.position = pose.position
        if source != "gizmo":
            self.gizmo.wxyz = pose.wxyz
            self.gizmo.position = pose.position
        for listener in self._listeners:
            listener(pose, source)

    def to_world(self, path: str, point: tf.Vector) -> tuple[float, float, float]:
        """A point given in the frame drawn at scene ``path``, in world coordinates."""
        p = np.asarray(point, dtype=np.float64).reshape(1, 3)
        if path == CAMERA_PATH:
            p = tf.apply(self.pose.matrix(), p)
        return tf.as_xyz(p[0])

    def show_marks(self, *, frames: bool, frustum: bool) -> None:
        """Show or hide the desk's own marks: both frames' axes and names, and the frustum.

        The frame nodes themselves stay visible: points, clouds and markers
        stamped in base_link or camera hang under them and keep showing.
        """
        self.base.show_axes = self.camera.show_axes = frames
        self.base_label.visible = self.camera_label.visible = frames
        self.frustum.visible = frustum

    def show_gizmo(self, visible: bool) -> None:
        self.gizmo.visible = visible

    def _on_gizmo(self, _event: object) -> None:
        # The gizmo lives at the scene root, and base_link sits at the root
        # with identity pose, so its pose is the camera pose in base_link.
        self.set_pose(CameraPose.from_wxyz_position(self.gizmo.wxyz, self.gizmo.position), "gizmo")
