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

import numpy as np
import viser
from nav_msgs.msg import Path
from rclpy.node import Node

from app.scene.framed_layer import FramedLayer, frame_of

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


class PathLayer(FramedLayer):
    """Draws the Path topic picked (``select``) under its TF frame."""

    NODE_NAME = NODE_NAME
    MSG_TYPE = Path

    def __init__(
        self,
        node: Node,
        server: viser.ViserServer,
        frame_known: Callable[[str], bool] | None = None,
    ) -> None:
        super().__init__(node, server, "nav-path", MAX_HZ, frame_known)
        self.poses_shown = 0

    def forget(self) -> None:
        super().forget()
        self.poses_shown = 0

    # --- worker thread ---
    def draw(self, msg: Path) -> None:
        frame = frame_of(msg.header.frame_id)
        points = path_points(msg)
        left_out = len(msg.poses) - len(points)
        self.poses_shown = len(points)
        if len(points) < 2:
            self.nothing_drawn(
                "an empty path (no plan)"
                if not msg.poses
                else f"{len(msg.poses)} pose(s): nothing to join into a line"
            )
            return
        self.show_segments(frame, polyline_segments(points), COLOUR, THICKNESS)
        self.drawn(
            frame,
            f"{len(points)} poses, {path_length(points):.1f} m"
            + (f" ({left_out} with a NaN or inf left out)" if left_out else ""),
        )
