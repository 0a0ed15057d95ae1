"""Draw one PointCloud2 topic the learner picks, throttled and under a point budget.

The subscription callback only hands the message to a :class:`LatestWorker`;
decoding (numpy, a few ms for 100k points) and the viser update run in the
worker thread. The cloud node is created once per frame and then updated in
place (``handle.points``/``handle.colors``), never re-added per message.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import viser
from rclpy.node import Node
from sensor_msgs.msg import PointCloud2

from app.scene import transforms as tf
from app.scene.cloud_codec import CloudFormatError, decode_cloud
from app.scene.follow import OneTopicLayer, TopicFollower
from app.scene.frames import scene_path_for_frame
from app.scene.latest import LatestWorker
from app.scene.topic_picker import NONE

Point3 = tuple[float, float, float]

DEFAULT_BUDGET = 200_000
MAX_HZ = 30.0  # above the 20 Hz a typical depth camera publishes, so none is skipped


def point_size_for(count: int) -> float:
    """Metres per point: a sparse SLAM map needs fat points, a dense depth cloud thin ones."""
    if count < 5_000:
        return 0.02
    if count < 50_000:
        return 0.01
    return 0.004


@dataclass(frozen=True)
class CloudStatus:
    topic: str
    total: int = 0
    shown: int = 0
    budget: int = DEFAULT_BUDGET
    colour_source: str = ""
    frame_id: str = ""
    frame_known: bool = True
    stamp: str = ""
    error: str = ""
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0)  # in the cloud's frame
    radius: float = 0.0  # half the bounding-box diagonal, metres


class PointCloudLayer(OneTopicLayer):
    def __init__(self, node: Node, server: viser.ViserServer) -> None:
        self._server = server
        self._lock = threading.Lock()  # the status: the worker writes, the UI thread reads
        self._draw_lock = threading.Lock()  # the handle: the worker draws, the UI thread removes
        self._handle: viser.PointCloudHandle | None = None
        self._handle_path = ""
        self.budget = DEFAULT_BUDGET
        self._status = CloudStatus(NONE)
        worker = LatestWorker("cloud", self._draw, MAX_HZ)
        super().__init__(TopicFollower(node, worker, PointCloud2, on_switch=self._forget))

    @property
    def status(self) -> CloudStatus:
        with self._lock:
            return self._status

    def select(self, topic: str) -> None:
        """Follow ``topic`` (or nothing, for "(none)"): one subscription at a time."""
        if self._follower.select(topic) and topic == NONE:
            self._remove_handle()

    def _forget(self, topic: str) -> None:
        with self._lock:
            self._status = CloudStatus(topic, budget=self.budget)

    def _remove_handle(self) -> None:
        with self._draw_lock:
            self._remove_handle_locked()

    def _remove_handle_locked(self) -> None:
        if self._handle is not None:
            self._handle.remove()
            self._handle = None
            self._handle_path = ""

    def _draw(self, msg: PointCloud2) -> None:
        with self._draw_lock:
            self._draw_locked(msg)
        if self.on_drawn is not None:
            self.on_drawn(self.status)

    def _draw_locked(self, msg: PointCloud2) -> None:
        if self.topic == NONE:  # unpicked while this message waited
            return
        budget = self.budget
        stamp = f"{msg.header.stamp.sec}.{msg.header.stamp.nanosec:09d}"
        try:
            cloud = decode_cloud(msg, budget)
        except CloudFormatError as exc:
            with self._lock:
                self._status = CloudStatus(self.topic, budget=budget, error=str(exc))
            return
        parent, known = scene_path_for_frame(msg.header.frame_id, self.topic)
        path = f"{parent}/cloud"
        centre, radius = (0.0, 0.0, 0.0), 0.0
        if cloud.shown:
            lo, hi = cloud.points.min(axis=0), cloud.points.max(axis=0)
            centre = tf.as_xyz((lo + hi) / 2)
            radius = float(np.linalg.norm(hi - lo)) / 2
        size = point_size_for(cloud.shown)
        if self._handle is not None and self._handle_path == path:
            with self._server.atomic():
                self._handle.points = cloud.points
                self._handle.colors = cloud.colors
                if self._handle.point_size != size:
                    self._handle.point_size = size
        else:
            self._remove_handle_locked()
            self._handle = self._server.scene.add_point_cloud(
                path,
                points=cloud.points,
                colors=cloud.colors,
                point_size=size,
                point_shape="square",
                point_shading="flat",
            )
            self._handle_path = path
        with self._lock:
            self._status = CloudStatus(
                self.topic,
                total=cloud.total,
                shown=cloud.shown,
                centre=centre,
                radius=radius,
                budget=budget,
                colour_source=cloud.colour_source,
                frame_id=msg.header.frame_id,
                frame_known=known,
                stamp=stamp,
            )

    # set by the panel: refresh the status line right after a draw
    on_drawn: Callable[[CloudStatus], None] | None = None

    def frame_in_view(self, world_from_frame: Callable[[str, Point3], Point3]) -> bool:
        """Point every browser's camera at the cloud; False when nothing is drawn yet."""
        s = self.status
        if not s.shown or self._handle is None:
            return False
        centre = world_from_frame(self._handle_path.rsplit("/", 1)[0], s.centre)
        distance = max(1.5 * s.radius, 0.5)
        eye = np.asarray(centre) + distance * np.array([1.0, -1.0, 0.8])
        for client in self._server.get_clients().values():
            with client.atomic():
                client.camera.position = tf.as_xyz(eye)
                client.camera.look_at = tf.as_xyz(centre)
        return True

    def describe(self) -> str:
        """Markdown for the panel: how many points, which budget, colouring, frame."""
        s = self.status
        if s.topic == NONE:
            return ""
        if s.error:
            return f"⚠️ cannot draw `{s.topic}`: {s.error}"
        if not s.total:
            return ""
        cut = (
            f"showing **{s.shown:,}** of {s.total:,} points (budget {s.budget:,}: every "
            f"{-(-s.total // s.shown) if s.shown else 1}th point)"
            if s.shown < s.total and s.total > s.budget
            else f"**{s.shown:,}** points (budget {s.budget:,})"
        )
        frame = f"frame `{s.frame_id or '(empty)'}`"
        if not s.frame_known:
            frame += " (unknown here: drawn at base_link)"
        return f"{cut} · colour: {s.colour_source} · {frame} · stamp {s.stamp}"
