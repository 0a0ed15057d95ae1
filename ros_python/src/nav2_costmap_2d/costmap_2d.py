"""A 2D costmap from an OccupancyGrid: Nav2's static layer and inflation layer, in numpy.

The cells hold Nav2's costs (``cost_values``): 0 free, 1..252 near an
obstacle, 253 *inscribed* (the robot's centre here puts its body into an
obstacle), 254 *lethal* (an obstacle), 255 *no information* (unknown).

- The static layer reads each map cell as Nav2's ``StaticLayer`` does:
  unknown (-1) is NO_INFORMATION when ``track_unknown_space`` (else free),
  a value at or above ``lethal_cost_threshold`` (100) is LETHAL, the rest
  free (``trinary_costmap``) or scaled.
- The inflation layer gives every cell within ``inflation_radius`` of a
  lethal cell the cost Nav2's ``InflationLayer`` computes from the distance
  ``d`` (m): LETHAL at the obstacle, INSCRIBED while ``d <= inscribed_radius``,
  then ``252 * exp(-cost_scaling_factor * (d - inscribed_radius))``, and
  keeps the higher of that and the cell's own cost. Unknown cells stay
  unknown unless inflation makes them inscribed (``inflate_unknown`` false).

Rows are y, columns x, as the OccupancyGrid's data (row-major from the
bottom-left cell at ``origin``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from nav2_costmap_2d.cost_values import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    MAX_NON_OBSTACLE,
    NO_INFORMATION,
)


@dataclass
class Costmap2D:
    """A grid of costs and where it lies in its frame."""

    costs: np.ndarray  # uint8, shape (size_y, size_x)
    resolution: float  # m per cell
    origin_x: float  # m, the outer corner of cell (0, 0)
    origin_y: float
    frame_id: str = "map"

    @property
    def size_x(self) -> int:
        return int(self.costs.shape[1])

    @property
    def size_y(self) -> int:
        return int(self.costs.shape[0])

    def world_to_map(self, wx: float, wy: float) -> tuple[int, int] | None:
        """The cell (mx, my) holding a point, or None outside the map (``worldToMap``)."""
        if not (math.isfinite(wx) and math.isfinite(wy)):
            return None
        if wx < self.origin_x or wy < self.origin_y:
            return None
        mx = int((wx - self.origin_x) / self.resolution)
        my = int((wy - self.origin_y) / self.resolution)
        if mx >= self.size_x or my >= self.size_y:
            return None
        return mx, my

    def map_to_world(self, mx: float, my: float) -> tuple[float, float]:
        """The centre of cell (mx, my) in metres (``mapToWorld``)."""
        return (
            self.origin_x + (mx + 0.5) * self.resolution,
            self.origin_y + (my + 0.5) * self.resolution,
        )

    def get_cost(self, mx: int, my: int) -> int:
        return int(self.costs[my, mx])

    def copy(self) -> Costmap2D:
        return Costmap2D(
            self.costs.copy(), self.resolution, self.origin_x, self.origin_y, self.frame_id
        )


def static_layer(
    data: np.ndarray,
    *,
    track_unknown_space: bool = True,
    lethal_cost_threshold: int = 100,
    trinary_costmap: bool = True,
) -> np.ndarray:
    """OccupancyGrid values (int8, -1..100, shape (h, w)) to Nav2 costs (``interpretValue``)."""
    values = np.asarray(data).astype(np.int16)
    if trinary_costmap:
        costs = np.full(values.shape, FREE_SPACE, np.uint8)
    else:
        scaled = np.clip(values, 0, lethal_cost_threshold) / float(lethal_cost_threshold)
        costs = (scaled * LETHAL_OBSTACLE).astype(np.uint8)
    costs[values >= lethal_cost_threshold] = LETHAL_OBSTACLE
    unknown = values < 0
    costs[unknown] = NO_INFORMATION if track_unknown_space else FREE_SPACE
    return costs


def inflation_cost(
    distance: np.ndarray | float, inscribed_radius: float, cost_scaling_factor: float
) -> np.ndarray:
    """The inflation layer's cost at ``distance`` metres from the nearest obstacle."""
    d = np.asarray(distance, dtype=np.float64)
    factor = np.exp(-cost_scaling_factor * (d - inscribed_radius))
    cost = ((INSCRIBED_INFLATED_OBSTACLE - 1) * factor).astype(np.int64)
    cost = np.where(d <= inscribed_radius + 1e-9, INSCRIBED_INFLATED_OBSTACLE, cost)
    cost = np.where(d <= 0.0, LETHAL_OBSTACLE, cost)
    return np.clip(cost, FREE_SPACE, LETHAL_OBSTACLE).astype(np.uint8)


def distance_to_lethal(costs: np.ndarray) -> np.ndarray:
    """Euclidean distance (cells) from each cell centre to the nearest lethal cell's centre."""
    if not np.any(costs == LETHAL_OBSTACLE):
        return np.full(costs.shape, np.inf)
    free = (costs != LETHAL_OBSTACLE).astype(np.uint8)
    return cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE).astype(np.float64)


def inflate(
    costs: np.ndarray,
    resolution: float,
    *,
    inflation_radius: float = 0.55,
    cost_scaling_factor: float = 3.0,
    inscribed_radius: float = 0.15,
    inflate_unknown: bool = False,
) -> np.ndarray:
    """The inflation layer over ``costs`` (a new array; ``costs`` is not changed)."""
    distance = distance_to_lethal(costs) * resolution
    reach = distance <= max(inflation_radius, inscribed_radius) + 1e-9
    inflated = np.zeros(costs.shape, np.uint8)
    inflated[reach] = inflation_cost(distance[reach], inscribed_radius, cost_scaling_factor)
    out = np.maximum(costs, inflated)
    unknown = costs == NO_INFORMATION
    threshold = 1 if inflate_unknown else INSCRIBED_INFLATED_OBSTACLE
    out[unknown] = np.where(inflated[unknown] >= threshold, inflated[unknown], NO_INFORMATION)
    return out


def costmap_from_grid(
    data: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    *,
    frame_id: str = "map",
    robot_radius: float = 0.15,
    inflation_radius: float = 0.55,
    cost_scaling_factor: float = 3.0,
    track_unknown_space: bool = True,
    inflate_unknown: bool = False,
) -> Costmap2D:
    """Static layer + inflation layer over an OccupancyGrid's cells (shape (h, w))."""
    costs = static_layer(data, track_unknown_space=track_unknown_space)
    costs = inflate(
        costs,
        resolution,
        inflation_radius=inflation_radius,
        cost_scaling_factor=cost_scaling_factor,
        inscribed_radius=robot_radius,
        inflate_unknown=inflate_unknown,
    )
    return Costmap2D(costs, float(resolution), float(origin[0]), float(origin[1]), frame_id)


def _translation_table() -> np.ndarray:
    """Costs to OccupancyGrid values as Nav2's costmap publisher translates them."""
    table = np.zeros(256, np.int8)
    for cost in range(1, MAX_NON_OBSTACLE + 1):
        table[cost] = 1 + (97 * (cost - 1)) // 251
    table[INSCRIBED_INFLATED_OBSTACLE] = 99
    table[LETHAL_OBSTACLE] = 100
    table[NO_INFORMATION] = -1
    return table


COST_TRANSLATION_TABLE = _translation_table()


def to_occupancy_values(costs: np.ndarray) -> np.ndarray:
    """The int8 values ``<name>/costmap`` (nav_msgs/OccupancyGrid) carries for these costs."""
    return COST_TRANSLATION_TABLE[np.asarray(costs, np.uint8)]
