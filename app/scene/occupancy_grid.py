"""A nav_msgs/OccupancyGrid drawn on the floor, as rviz's Map display draws /map.

The grid becomes one picture (a cell a pixel) laid flat just above the floor
of its frame (``header.frame_id``, usually ``map``): it hangs under the TF
view's node of that frame, so the map sits wherever TF puts it in the Fixed
Frame and moves with it (as the simulated world's markers do). Free cells are
white, occupied cells black, unknown cells a faint grey you can see the
floor through; values between 1 and 99 (a costmap, a map_server in scale
mode) are greys in between. The map's origin (its lower-left cell) and its
turn about z are honoured. A frame not on TF yet: the map is drawn at the
Fixed Frame's origin until the frame comes, and ``describe()`` says so.

Maps are latched (reliable, transient local): the subscription asks for that
whenever every publisher offers it, so a map published once (map_server)
still arrives when the topic is picked later.

Threads: the executor hands the newest map to a worker (at most twice a
second); the worker converts and draws; the UI thread picks the topic.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import viser
from nav_msgs.msg import OccupancyGrid
from rclpy.node import Node
from rclpy.subscription import Subscription

from app.ros.qos import matching_qos
from app.scene.latest import LatestWorker
from app.scene.qos import SCENE_CALLBACK_GROUP
from app.scene.tf_view import TF_PATH, scene_name
from app.scene.topic_picker import NONE

MAX_HZ = 2.0
TYPES = ("nav_msgs/msg/OccupancyGrid",)
LIFT = 0.02  # m above the frame's floor: clear of the floor's own drawing
FREE_RGBA = (245, 245, 245, 215)
OCCUPIED_RGBA = (15, 15, 15, 255)
UNKNOWN_RGBA = (120, 130, 140, 60)
NODE_NAME = "occupancy_grid"


def grid_image(data: Any, width: int, height: int) -> np.ndarray:
    """RGBA pixels (height, width, 4) of a map's cells, row 0 the map's first row.

    viser lays an image with its first row towards the plane's -y edge, so the
    rows go in as the map stores them (row 0 at the origin's side).
    """
    cells = np.asarray(data, dtype=np.int16).reshape(height, width)
    image = np.empty((height, width, 4), np.uint8)
    known = (cells >= 0) & (cells <= 100)
    shade = np.clip(cells, 0, 100).astype(np.float64) / 100.0
    for channel in range(3):
        free, occupied = FREE_RGBA[channel], OCCUPIED_RGBA[channel]
        image[:, :, channel] = np.rint(free + (occupied - free) * shade).astype(np.uint8)
    image[:, :, 3] = np.rint(FREE_RGBA[3] + (OCCUPIED_RGBA[3] - FREE_RGBA[3]) * shade).astype(
        np.uint8
    )
    image[~known] = UNKNOWN_RGBA
    return image


def placement(
    msg: OccupancyGrid,
) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """(centre position, wxyz) of the map's picture in its frame: the origin is its corner."""
    info = msg.info
    q = info.origin.orientation
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    half_w, half_h = info.width * info.resolution / 2.0, info.height * info.resolution / 2.0
    c, s = math.cos(yaw), math.sin(yaw)
    x = info.origin.position.x + c * half_w - s * half_h
    y = info.origin.position.y + s * half_w + c * half_h
    return (x, y, info.origin.position.z + LIFT), (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


class OccupancyGridLayer:
    """Draws the OccupancyGrid topic picked (``select``) under its TF frame.

    ``frame_known(frame)`` says whether TF has that frame now (the note warns
    when not); by default every frame counts as known.
    """

    def __init__(
        self,
        node: Node,
        server: viser.ViserServer,
        frame_known: Any = None,
    ) -> None:
        self._node = node
        self._server = server
        self._frame_known = frame_known or (lambda _frame: True)
        self._subscription: Subscription | None = None
        self._handle: Any = None
        self._path = ""
        self.topic = NONE
        self.note = ""
        self._frame: str | None = None  # the drawn map's frame; None: nothing drawn
        self.cells_known = 0
        self.worker = LatestWorker("occupancy-grid", self.draw, MAX_HZ)

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
                OccupancyGrid, topic, self.worker.offer, qos, callback_group=SCENE_CALLBACK_GROUP
            )

    def _forget(self) -> None:
        handle, self._handle = self._handle, None
        if handle is not None:
            handle.remove()
        self.note = ""
        self._frame = None
        self.cells_known = 0

    def close(self) -> None:
        self.select(NONE)
        self.worker.stop()

    # --- worker thread ---
    def draw(self, msg: OccupancyGrid) -> None:
        info = msg.info
        width, height = int(info.width), int(info.height)
        frame = msg.header.frame_id.strip().lstrip("/")
        self._frame = None
        if width * height == 0 or len(msg.data) != width * height:
            self.note = (
                f"⚠️ not drawn: {len(msg.data)} cells for a {width} x {height} map"
                if width * height
                else "an empty map (0 cells)"
            )
            return
        if not (math.isfinite(info.resolution) and info.resolution > 0.0):
            self.note = f"⚠️ not drawn: resolution {info.resolution} m is not positive"
            return
        image = grid_image(msg.data, width, height)
        position, wxyz = placement(msg)
        parent = f"{TF_PATH}/frames/{scene_name(frame)}" if frame else TF_PATH
        path = f"{parent}/{NODE_NAME}"
        if path != self._path and self._handle is not None:
            self._handle.remove()  # the map moved to another frame
        self._path = path
        self._handle = self._server.scene.add_image(
            path,
            image,
            render_width=width * info.resolution,
            render_height=height * info.resolution,
            format="png",
            position=position,
            wxyz=wxyz,
            cast_shadow=False,
            receive_shadow=False,
        )
        known = int((np.asarray(msg.data) >= 0).sum())
        self.cells_known = known
        self._frame = frame
        self.note = (
            f"{width} x {height} cells of {info.resolution:g} m "
            f"({width * info.resolution:.1f} m x {height * info.resolution:.1f} m), "
            f"{100.0 * known / (width * height):.0f} % known"
        )

    def describe(self) -> str:
        """What was drawn and where; asked again at each refresh (TF may bring the frame later)."""
        note, frame = self.note, self._frame
        if frame is None:
            return note
        if not frame or not self._frame_known(frame):
            return f"{note}, ⚠️ frame `{frame or '(empty)'}` is not on TF: drawn at the origin"
        return f"{note}, in `{frame}`"
