"""The picked camera image on a frustum at its TF frame, shaped by the camera's intrinsics.

rviz's Camera display: an image whose ``header.frame_id`` is a TF frame
(``camera_optical_frame``: z forward, x right, y down, the convention viser's
frustums follow too) is shown on a frustum at that frame, so it rides along
with the robot. The frustum's opening comes from ``K`` in the
``camera_info`` beside the image topic (``/camera/image_raw`` ->
``/camera/camera_info``): vertical field of view ``2 atan(h / 2 fy)``,
aspect ``w / h``. Until a camera_info arrives, the image's own aspect and a
default opening are used, and the note says so.

Threads: ``follow`` runs on the UI thread (it subscribes); ``show`` on the
image layer's worker; the camera_info callback (executor) stores one tuple.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection

import numpy as np
import viser
from rclpy.node import Node
from rclpy.subscription import Subscription
from sensor_msgs.msg import CameraInfo

from app.scene.qos import SCENE_CALLBACK_GROUP
from app.scene.sim_world import tf_frame_path

DEFAULT_FOV = 1.0  # rad, until a camera_info says better
FRUSTUM_SCALE = 0.25  # m
NODE = "camera_view"


def info_topic_for(image_topic: str) -> str:
    """The camera_info published beside an image topic, as image_transport pairs them."""
    return image_topic.rsplit("/", 1)[0] + "/camera_info"


def frustum_shape(
    k: tuple[float, ...] | list[float] | None, width: int, height: int
) -> tuple[float, float]:
    """(vertical field of view in rad, aspect w / h) from a 3x3 K, row major (or a default)."""
    aspect = width / max(1, height)
    if k is None or len(k) != 9 or not k[4] > 0 or not all(map(math.isfinite, k)):
        return DEFAULT_FOV, aspect
    return 2.0 * math.atan2(height / 2.0, k[4]), aspect


class TfCamera:
    def __init__(
        self, node: Node, server: viser.ViserServer, tf_frames: Callable[[], Collection[str]]
    ) -> None:
        self._node = node
        self._server = server
        self._tf_frames = tf_frames
        self._info: tuple[tuple[float, ...], int, int] | None = None
        self._subscription: Subscription | None = None
        self._handle: viser.CameraFrustumHandle | None = None
        self._shape: tuple[str, float, float] | None = None  # frame, fov, aspect drawn
        self.note = ""

    # --- UI thread ---
    def follow(self, image_topic: str | None) -> None:
        """Listen to the camera_info beside ``image_topic`` (None: the image went away)."""
        if self._subscription is not None:
            self._node.destroy_subscription(self._subscription)
            self._subscription = None
        self._info = None
        self.note = ""
        self._take_away()
        if image_topic:
            self._subscription = self._node.create_subscription(
                CameraInfo,
                info_topic_for(image_topic),
                self._on_info,
                5,
                callback_group=SCENE_CALLBACK_GROUP,
            )

    def close(self) -> None:
        self.follow(None)

    # --- executor thread ---
    def _on_info(self, msg: CameraInfo) -> None:
        self._info = (tuple(float(v) for v in msg.k), int(msg.width), int(msg.height))

    # --- the image layer's worker ---
    def show(self, frame_id: str, rgb: np.ndarray, width: int, height: int) -> bool:
        """Put ``rgb`` on the frustum at ``frame_id``; False if that frame is not on TF."""
        frame = frame_id.strip().lstrip("/")
        if not frame or frame not in self._tf_frames():
            self._take_away()
            return False
        info = self._info
        k = info[0] if info is not None else None
        fov, aspect = frustum_shape(k, *(info[1:] if info is not None else (width, height)))
        shape = (frame, round(fov, 4), round(aspect, 4))
        if self._handle is None or shape != self._shape:
            self._take_away()
            self._handle = self._server.scene.add_camera_frustum(
                f"{tf_frame_path(frame)}/{NODE}",
                fov=fov,
                aspect=aspect,
                scale=FRUSTUM_SCALE,
                thickness=0.004,
                color=(40, 90, 200),
                image=rgb,
                format="jpeg",
                jpeg_quality=80,
            )
            self._shape = shape
        else:
            self._handle.image = rgb
        source = "its camera_info" if info is not None else "a default (no camera_info yet)"
        self.note = (
            f"On the camera at TF frame `{frame}`: field of view "
            f"{math.degrees(fov):.0f}° from {source}."
        )
        return True

    def _take_away(self) -> None:
        handle, self._handle = self._handle, None
        self._shape = None
        if handle is not None:
            handle.remove()
