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

Maps are latched (reliable, transient local), and the subscription asks for
that (app/scene/framed_layer.py, which also places the picture and says
where), so a map published once (map_server) still arrives when the topic
is picked later. At most two maps a second are drawn.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import viser
from nav_msgs.msg import OccupancyGrid
from rclpy.node import Node

from app.scene.framed_layer import FramedLayer, frame_of

if TYPE_CHECKING:
    import numpy.typing as npt

MAX_HZ = 2.0
TYPES = ("nav_msgs/msg/OccupancyGrid",)
LIFT = 0.02  # m above the frame's floor: clear of the floor's own drawing
FREE_RGBA = (245, 245, 245, 215)
OCCUPIED_RGBA = (15, 15, 15, 255)
UNKNOWN_RGBA = (120, 130, 140, 60)
NODE_NAME = "occupancy_grid"


def grid_image(data: npt.ArrayLike, width: int, height: int) -> np.ndarray:
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


class OccupancyGridLayer(FramedLayer):
    """Draws the OccupancyGrid topic picked (``select``) under its TF frame.

    ``frame_known(frame)`` says whether TF has that frame now (the note warns
    when not); by default every frame counts as known.
    """

    NODE_NAME = NODE_NAME
    MSG_TYPE = OccupancyGrid

    def __init__(
        self,
        node: Node,
        server: viser.ViserServer,
        frame_known: Callable[[str], bool] | None = None,
    ) -> None:
        super().__init__(node, server, "occupancy-grid", MAX_HZ, frame_known)
        self.cells_known = 0

    def forget(self) -> None:
        super().forget()
        self.cells_known = 0

    # --- worker thread ---
    def draw(self, msg: OccupancyGrid) -> None:
        info = msg.info
        width, height = int(info.width), int(info.height)
        frame = frame_of(msg.header.frame_id)
        if width * height == 0 or len(msg.data) != width * height:
            self.nothing_drawn(
                f"⚠️ not drawn: {len(msg.data)} cells for a {width} x {height} map"
                if width * height
                else "an empty map (0 cells)"
            )
            return
        if not (math.isfinite(info.resolution) and info.resolution > 0.0):
            self.nothing_drawn(f"⚠️ not drawn: resolution {info.resolution} m is not positive")
            return
        position, wxyz = placement(msg)
        self.show_image(
            frame,
            image=grid_image(msg.data, width, height),
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
        self.drawn(
            frame,
            f"{width} x {height} cells of {info.resolution:g} m "
            f"({width * info.resolution:.1f} m x {height * info.resolution:.1f} m), "
            f"{100.0 * known / (width * height):.0f} % known",
        )
