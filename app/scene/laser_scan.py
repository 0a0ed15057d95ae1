"""A sensor_msgs/LaserScan drawn as points where its frame is, as rviz's LaserScan display.

Each ray's range becomes a point in the scan's frame (``header.frame_id``,
the lidar); the points are then placed with that frame's pose in the Fixed
Frame at the moment the scan is drawn, and stay there until the next scan,
as rviz leaves a scan where it was seen. Rays with no return (``inf``,
REP 117), too close (``-inf``, or under ``range_min``) or past ``range_max``
draw nothing. A scan whose frame is not on TF is drawn at the origin, and
the note says so.

Threads: the executor hands the newest scan to a worker (at most 10 a
second); the worker converts and draws.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import viser
from rclpy.node import Node
from sensor_msgs.msg import LaserScan

from app.scene.follow import OneTopicLayer, TopicFollower
from app.scene.latest import LatestWorker

MAX_HZ = 10.0
SCAN_PATH = "/laser_scan"
POINT_SIZE = 0.03  # m
NEAR, FAR = np.array([230, 40, 40]), np.array([250, 200, 40])  # colour by range: red near


def scan_points(
    ranges: np.ndarray | list[float],
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
) -> tuple[np.ndarray, np.ndarray]:
    """(points (N, 3) in the scan's frame, their ranges (N,)) of the rays that hit something."""
    r = np.asarray(ranges, dtype=np.float64)
    angles = angle_min + np.arange(len(r)) * angle_increment
    valid = np.isfinite(r) & (r >= range_min) & (r <= range_max) & (r > 0.0)
    r, angles = r[valid], angles[valid]
    points = np.stack([r * np.cos(angles), r * np.sin(angles), np.zeros_like(r)], axis=1)
    return points.astype(np.float32), r


def range_colours(r: np.ndarray, range_max: float) -> np.ndarray:
    """Red near, yellow far: walls at a glance."""
    t = np.clip(r / max(range_max, 1e-6), 0.0, 1.0)[:, None]
    return ((1.0 - t) * NEAR + t * FAR).astype(np.uint8)


class LaserScanLayer(OneTopicLayer):
    def __init__(
        self,
        node: Node,
        server: viser.ViserServer,
        frame_pose: Callable[[str], np.ndarray | None],
    ) -> None:
        """``frame_pose(frame)``: the frame's 4x4 pose in the Fixed Frame now, or None."""
        self._server = server
        self._frame_pose = frame_pose
        self._handle: viser.PointCloudHandle | None = None
        self.note = ""
        self.points_shown = 0
        worker = LatestWorker("laser-scan", self._draw, MAX_HZ)
        super().__init__(TopicFollower(node, worker, LaserScan, on_switch=self._forget))

    def _forget(self, _topic: str) -> None:
        """UI thread, when the topic changes: take the old scan away."""
        handle, self._handle = self._handle, None
        if handle is not None:
            handle.remove()
        self.note = ""
        self.points_shown = 0

    def _draw(self, msg: LaserScan) -> None:
        points, ranges = scan_points(
            msg.ranges, msg.angle_min, msg.angle_increment, msg.range_min, msg.range_max
        )
        frame = msg.header.frame_id.strip().lstrip("/")
        pose = self._frame_pose(frame) if frame else None
        where = f"in `{frame}`"
        if pose is None:
            where = f"⚠️ frame `{frame or '(empty)'}` is not on TF: drawn at the origin"
        else:
            points = (points @ pose[:3, :3].T + pose[:3, 3]).astype(np.float32)
        colours = range_colours(ranges, msg.range_max)
        if len(points) == 0:  # nothing in range: keep one invisible point, not an empty cloud
            points, colours = np.zeros((1, 3), np.float32), np.zeros((1, 3), np.uint8)
        handle = self._handle
        if handle is None:
            self._handle = self._server.scene.add_point_cloud(
                f"{SCAN_PATH}/points",
                points=points,
                colors=colours,
                point_size=POINT_SIZE,
                point_shape="circle",
            )
        else:
            handle.points = points
            handle.colors = colours
        self.points_shown = len(ranges)
        self.note = f"{len(ranges)} of {len(msg.ranges)} rays hit something, {where}"
