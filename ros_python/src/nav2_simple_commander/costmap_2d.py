"""PyCostmap2D: a costmap published as nav_msgs/OccupancyGrid, read as Nav2's Costmap2D reads.

Nav2's costmaps publish on ``<costmap>/costmap`` as OccupancyGrid; Nav2's
demos wrap a received one in ``PyCostmap2D`` to ask for a cell's cost and to
convert between map cells and world metres with the same names and
conventions as the C++ ``nav2_costmap_2d::Costmap2D``: cell (0, 0) is the
origin's corner, a cell's world point is its centre, the index is row-major
from the bottom row (``my * size_x + mx``), costs are 0-255 (an unknown -1
reads as 255, NO_INFORMATION).
"""

from __future__ import annotations

from typing import Any

import numpy as np


class PyCostmap2D:
    """Costmap Python3 API for OccupancyGrids to populate from published messages."""

    def __init__(self, occupancy_map: Any) -> None:
        info = occupancy_map.info
        self.size_x: int = info.width
        self.size_y: int = info.height
        self.resolution: float = info.resolution
        self.origin_x: float = info.origin.position.x
        self.origin_y: float = info.origin.position.y
        self.global_frame_id: str = occupancy_map.header.frame_id
        self.costmap_timestamp = occupancy_map.header.stamp
        # OccupancyGrid cells are int8: -1 (unknown) becomes 255 as a uint8 cost.
        self.costmap = np.asarray(occupancy_map.data, dtype=np.int8).astype(np.uint8)

    def getSizeInCellsX(self) -> int:
        """Get map width in cells."""
        return self.size_x

    def getSizeInCellsY(self) -> int:
        """Get map height in cells."""
        return self.size_y

    def getSizeInMetersX(self) -> float:
        """Get x axis map size in meters (to the last cell's centre, as Costmap2D says)."""
        return (self.size_x - 0.5) * self.resolution

    def getSizeInMetersY(self) -> float:
        """Get y axis map size in meters (to the last cell's centre, as Costmap2D says)."""
        return (self.size_y - 0.5) * self.resolution

    def getOriginX(self) -> float:
        """Get the origin x axis of the map [m]."""
        return self.origin_x

    def getOriginY(self) -> float:
        """Get the origin y axis of the map [m]."""
        return self.origin_y

    def getResolution(self) -> float:
        """Get map resolution [m/cell]."""
        return self.resolution

    def getGlobalFrameID(self) -> str:
        """Get global frame_id."""
        return self.global_frame_id

    def getCostmapTimestamp(self) -> Any:
        """Get costmap timestamp."""
        return self.costmap_timestamp

    def getCostXY(self, mx: int, my: int) -> np.uint8:
        """Get the cost of the cell at map coordinates (mx, my)."""
        return np.uint8(self.costmap[self.getIndex(mx, my)])

    def getCostIdx(self, index: int) -> np.uint8:
        """Get the cost of the cell at ``index``."""
        return np.uint8(self.costmap[index])

    def setCost(self, mx: int, my: int, cost: int | np.uint8) -> None:
        """Set the cost of the cell at map coordinates (mx, my)."""
        self.costmap[self.getIndex(mx, my)] = cost

    def mapToWorld(self, mx: int, my: int) -> tuple[float, float]:
        """The world point (wx, wy) [m] at the centre of cell (mx, my)."""
        return (
            self.origin_x + (mx + 0.5) * self.resolution,
            self.origin_y + (my + 0.5) * self.resolution,
        )

    def worldToMapValidated(self, wx: float, wy: float) -> tuple[int, int] | tuple[None, None]:
        """The cell (mx, my) holding world point (wx, wy), or (None, None) off the map."""
        if wx < self.origin_x or wy < self.origin_y:
            return (None, None)
        mx = int((wx - self.origin_x) // self.resolution)
        my = int((wy - self.origin_y) // self.resolution)
        if mx < self.size_x and my < self.size_y:
            return (mx, my)
        return (None, None)

    def getIndex(self, mx: int, my: int) -> int:
        """The index of cell (mx, my) in the row-major data."""
        return my * self.size_x + mx
