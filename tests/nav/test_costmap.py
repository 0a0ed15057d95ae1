"""nav2_costmap_2d: the static layer and the inflation layer give Nav2's cost values."""

from __future__ import annotations

import math

import numpy as np
from nav2_costmap_2d import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, NO_INFORMATION
from nav2_costmap_2d.costmap_2d import costmap_from_grid, to_occupancy_values


def test_inflation_along_a_line_from_a_wall_falls_as_nav2_computes_it():
    grid = np.zeros((20, 40), np.int8)
    grid[:, 0] = 100  # a wall along x = 0
    grid[0, 39] = -1
    costmap = costmap_from_grid(
        grid, 0.05, (0.0, 0.0), robot_radius=0.15, inflation_radius=0.55, cost_scaling_factor=3.0
    )
    row = costmap.costs[10]
    assert row[0] == LETHAL_OBSTACLE
    assert all(row[1:4] == INSCRIBED_INFLATED_OBSTACLE)  # 0.05..0.15 m
    for cells in range(4, 12):
        d = cells * 0.05
        assert row[cells] == int(252 * math.exp(-3.0 * (d - 0.15))), cells
    assert all(np.diff(row[3:12].astype(int)) < 0)
    assert all(row[12:39] == 0)  # beyond inflation_radius
    assert costmap.costs[0, 39] == NO_INFORMATION
    values = to_occupancy_values(costmap.costs)
    assert values[10, 0] == 100 and values[10, 1] == 99 and values[0, 39] == -1
    assert costmap.world_to_map(-0.01, 0.5) is None and costmap.world_to_map(0.07, 0.5) == (1, 10)
