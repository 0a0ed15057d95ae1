"""A nav_msgs/Path (the planner's ``/plan``) drawn as a coloured line just above the floor.

As rviz's Path display: the poses joined in order, one line, under the TF
view's node of the path's frame (``header.frame_id``, usually ``map``), so
the plan lies on the map wherever TF puts it. The note says how many poses
and how long the path is. An empty path (Nav2 sends one when a goal ends
without a plan) takes the line away. A frame not on TF yet: drawn at the
Fixed Frame's origin, and ``describe()`` says so.

A plan is published once per (re)planning, so the subscription asks for the
last one kept (transient local) whenever every publisher offers it.

Threads: the executor hands the newest path to a worker (a few a second);
the worker converts and draws; the UI thread picks the topic.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import viser
from nav_msgs.msg import Path
from rclpy.node import Node
from rclpy.subscription import Subscription

from app.ros.qos import matching_qos
from app.scene.latest import LatestWorker
from app.scene.qos import SCENE_CALLBACK_GROUP
from app.scene.tf_view import TF_PATH, scene_name
from app.scene.topic_picker import NONE

MAX_HZ = 5.0
TYPES = ("nav_msgs/msg/Path",)
NODE_NAME = "nav_path"
LIFT = 0.05  # m above the frame's floor: over the map (0.02) and the particles (0.03)
COLOUR = (20, 90, 255)  # blue: apart from the scan's reds and yellows, the particles' green
THICKNESS = 4.0  # screen pixels


def path_points(msg: Path) -> np.ndarray:
    """(N, 3) positions of the path's poses, in order (non-finite ones left out)."""
    table = np.array(
        [(p.pose.position.x, p.pose.position.y, p.pose.position.z) for p in msg.poses],
        np.float64,
    ).reshape(-1, 3)
    return table[np.isfinite(table).all(axis=1)]


def polyline_segments(points: np.ndarray, lift: float = LIFT) -> np.ndarray:
    """(N - 1, 2, 3) float32 segments joining consecutive points, ``lift`` above each."""
    p = np.asarray(points, np.float64).reshape(-1, 3).copy()
    p[:, 2] += lift
    return np.stack([p[:-1], p[1:]], axis=1).astype(np.float32)


def path_length(points: np.ndarray) -> float:
    """Along the floor, pose to pose (m)."""
    p = np.asarray(points, np.float64).reshape(-1, 3)
    return float(np.linalg.norm(np.diff(p[:, :2], axis=0), axis=1).sum())


class PathLayer:
    """Draws the Path topic picked (``select``) under its TF frame."""

    def __init__(
        self,
        node: Node,
        server: viser.ViserServer,
        frame_known: Callable[[str], bool] | None = None,
    ) -> None:
        self._node = node
        self._server = server
        self._frame_known = frame_known or (lambda _frame: True)
        self._subscription: Subscription | None = None
        self._handle: Any = None
        self._path = ""
        self.topic = NONE
        self.note = ""
        self._frame: str | None = None  # the drawn path's frame; None: nothing drawn
        self.poses_shown = 0
        self.worker = LatestWorker("nav-path", self.draw, MAX_HZ)

    # --- UI thread ---
    def select(self, topic: str) -> None:
        """Draw ``topic`` from now on ("(none)": nothing)."""
        if topic == self.topic:
            return
        self.topic = topic
        if self._subscription is not None:
            self._node.destroy_subscription(self._subscription)
            self._subscription = None
        self.worker.reset()
        self._forget()
        if topic != NONE:
            qos = matching_qos(self._node, topic, depth=1, latched=True)
            self._subscription = self._node.create_subscription(
                Path, topic, self.worker.offer, qos, callback_group=SCENE_CALLBACK_GROUP
            )

    def _forget(self) -> None:
        self._forget_drawing()
        self.note = ""
        self._frame = None
        self.poses_shown = 0

    def close(self) -> None:
        self.select(NONE)
        self.worker.stop()

    # --- worker thread ---
    def draw(self, msg: Path) -> None:
        frame = msg.header.frame_id.strip().lstrip("/")
        points = path_points(msg)
        left_out = len(msg.poses) - len(points)
        if len(points) < 2:
            self._forget_drawing()
            self._frame = None
            self.poses_shown = len(points)
            self.note = (
                "an empty path (no plan)"
                if not msg.poses
                else f"{len(msg.poses)} pose(s): nothing to join into a line"
            )
            return
        parent = f"{TF_PATH}/frames/{scene_name(frame)}" if frame else TF_PATH
        path = f"{parent}/{NODE_NAME}"
        segments = polyline_segments(points)
        handle = self._handle
        if path != self._path or handle is None or len(handle.points) != len(segments):
            self._forget_drawing()
            self._path = path
            self._handle = self._server.scene.add_line_segments(
                path, segments, COLOUR, thickness=THICKNESS, thickness_units="screen"
            )
        else:
            handle.points = segments
        self.poses_shown = len(points)
        self._frame = frame
        self.note = f"{len(points)} poses, {path_length(points):.1f} m" + (
            f" ({left_out} with a NaN or inf left out)" if left_out else ""
        )

    def _forget_drawing(self) -> None:
        handle, self._handle = self._handle, None
        if handle is not None:
            handle.remove()

    def describe(self) -> str:
        """What was drawn and where; asked again at each refresh (TF may bring the frame later)."""
        note, frame = self.note, self._frame
        if frame is None:
            return note
        if not frame or not self._frame_known(frame):
            return f"{note}, ⚠️ frame `{frame or '(empty)'}` is not on TF: drawn at the origin"
        return f"{note}, in `{frame}`"
