"""Show one sensor_msgs/Image topic in a panel image, and on a camera frustum in 3D.

Images are converted and jpeg-encoded in a worker thread at most a few times a
second (a browser panel needs no 30 Hz), downscaled first so each frame is
a few tens of kilobytes. An image whose frame is on TF goes on a frustum at
that frame (``TfCamera``, as rviz's Camera display); otherwise, if asked, on
the lesson-13 camera's frustum.
"""

from __future__ import annotations

import numpy as np
import viser
from rclpy.node import Node
from sensor_msgs.msg import Image

from app.scene.follow import OneTopicLayer, TopicFollower
from app.scene.frames import FrameTree
from app.scene.image_codec import ImageFormatError, downscale, image_to_rgb
from app.scene.latest import LatestWorker
from app.scene.tf_camera import TfCamera
from app.scene.topic_picker import NONE

MAX_HZ = 10.0
PANEL_WIDTH = 480
FRUSTUM_WIDTH = 160


class ImageLayer(OneTopicLayer):
    def __init__(
        self,
        node: Node,
        gui: viser.GuiApi,
        frames: FrameTree | None,
        *,
        label: str | None = "Camera image",
        tf_camera: TfCamera | None = None,
    ) -> None:
        self._frames = frames
        self.tf_camera = tf_camera
        self.on_frustum = False
        self.info = ""
        self.frames_shown = 0
        blank = np.full((48, 64, 3), 235, dtype=np.uint8)  # placeholder until a frame arrives
        self.handle = gui.add_image(blank, label=label, format="jpeg", jpeg_quality=80)
        worker = LatestWorker("image", self._draw, MAX_HZ)
        super().__init__(TopicFollower(node, worker, Image, on_switch=self._forget))

    def _forget(self, topic: str) -> None:
        self.info = ""
        if self.tf_camera is not None:
            self.tf_camera.follow(None if topic == NONE else topic)

    def show_on_frustum(self, enabled: bool) -> None:
        """On the lesson camera's frustum too (a layer made without the 3D frames: never)."""
        self.on_frustum = enabled and self._frames is not None
        if not enabled and self._frames is not None:
            self._frames.frustum.image = None

    def _draw(self, msg: Image) -> None:
        try:
            rgb = image_to_rgb(msg)
        except (ImageFormatError, ValueError) as exc:
            self.info = f"⚠️ {exc}"
            return
        self.handle.image = np.ascontiguousarray(downscale(rgb, PANEL_WIDTH))
        small = np.ascontiguousarray(downscale(rgb, FRUSTUM_WIDTH))
        camera, frame = self.tf_camera, msg.header.frame_id
        on_tf = camera is not None and camera.show(frame, small, msg.width, msg.height)
        if self.on_frustum and not on_tf and self._frames is not None:
            frustum = self._frames.frustum
            frustum.aspect = msg.width / max(1, msg.height)
            frustum.image = small
        self.frames_shown += 1
        self.info = f"{msg.width}×{msg.height} `{msg.encoding}` · frame `{msg.header.frame_id}`"
