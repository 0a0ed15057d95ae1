"""The office world's map for Nav2 (``nodes/worlds/office/map.yaml`` + ``map.pgm``).

What a learner's map_saver would have written after a perfect mapping run:
the floor plan of ``nodes/worlds/office/world.xml`` at the lidar's height
(``app.lessons.checks._world_map``), rasterised at 5 cm cells in the world's
own coordinates (frame ``map`` = the world frame, so amcl's pose and the
simulation's ground truth can be compared directly). A cell is occupied when
an obstacle reaches into it (the plan's signed distance at its centre is at
most half a cell diagonal), free when it lies inside the building and clear
of every obstacle, unknown outside the outer walls. Written with
``nav2_map_server.map_io`` exactly as Nav2's map_saver writes maps.

``python -m nodes.common.office_map [folder]`` writes the two files again;
tests/nav/test_office_map.py checks that the shipped files are what this
makes now, so they cannot go stale when the world changes.
"""

from __future__ import annotations

import array
import math
import sys
from pathlib import Path

import numpy as np
from nav2_map_server.map_io import SaveParameters, try_write_map_to_file
from nav2_map_server.map_mode import MapMode
from nav_msgs.msg import OccupancyGrid

from app.lessons.checks._world_map import load_world_map
from nodes.common.occupancy_grid import FREE, OCCUPIED, UNKNOWN, cell_centres, plan_distance

WORLD = "office"
RESOLUTION = 0.05
ORIGIN = (-5.5, -4.5)  # m: the map's lower-left corner, 0.4 m beyond the outer walls
SIZE = (220, 180)  # cells: 11 m x 9 m
INSIDE = (-5.05, 5.05, -4.05, 4.05)  # the outer walls' centre lines: inside is known
FOLDER = Path(__file__).resolve().parents[1] / "worlds" / WORLD


def office_grid() -> OccupancyGrid:
    """The office's map as an OccupancyGrid (frame ``map``, stamp 0)."""
    plan = load_world_map(WORLD)
    width, height = SIZE
    xs, ys = cell_centres(ORIGIN, RESOLUTION, width, height)
    distance = plan_distance(plan.obstacles, xs, ys)
    x0, x1, y0, y1 = INSIDE
    inside = (xs > x0) & (xs < x1) & (ys > y0) & (ys < y1)
    data = np.full((height, width), UNKNOWN, np.int8)
    data[inside & (distance > 0.0)] = FREE
    data[distance <= RESOLUTION * math.sqrt(0.5)] = OCCUPIED
    msg = OccupancyGrid()
    msg.header.frame_id = "map"
    msg.info.resolution = RESOLUTION
    msg.info.width, msg.info.height = width, height
    msg.info.origin.position.x, msg.info.origin.position.y = ORIGIN
    msg.info.origin.orientation.w = 1.0
    msg.data = array.array("b", data.reshape(-1).tobytes())
    return msg


def write_office_map(folder: Path = FOLDER) -> Path:
    """Write ``map.pgm`` and ``map.yaml`` into ``folder``; the YAML's path."""
    folder.mkdir(parents=True, exist_ok=True)
    params = SaveParameters(
        map_file_name=str(folder / "map"),
        image_format="pgm",
        free_thresh=0.25,
        occupied_thresh=0.65,
        mode=MapMode.TRINARY,
    )
    try_write_map_to_file(office_grid(), params)
    return folder / "map.yaml"


if __name__ == "__main__":
    print(write_office_map(Path(sys.argv[1]) if len(sys.argv) > 1 else FOLDER))
