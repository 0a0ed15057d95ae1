"""nav2_costmap_2d: the static, obstacle and inflation layers give Nav2's cost values."""

from __future__ import annotations

import math

import numpy as np
from nav2_costmap_2d import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
)
from nav2_costmap_2d.costmap_2d import (
    costmap_from_grid,
    inflate,
    static_layer,
    to_occupancy_values,
)
from nav2_costmap_2d.obstacle_layer import ObservationSource, ObstacleLayer, observation_from_scan


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


def room_scan(blocked, origin, count=360, rmax=8.0, res=0.05):
    """A noiseless 360-beam scan of a grid of blocked cells from ``origin`` (inf: nothing)."""
    angles = -math.pi + np.arange(count) * (2 * math.pi / count)
    steps = np.arange(0.0, rmax, 0.005)
    xs = origin[0] + steps[None, :] * np.cos(angles)[:, None]
    ys = origin[1] + steps[None, :] * np.sin(angles)[:, None]
    i, j = (xs / res).astype(int), (ys / res).astype(int)
    h, w = blocked.shape
    inside = (i >= 0) & (i < w) & (j >= 0) & (j < h)
    hit = np.zeros_like(inside)
    hit[inside] = blocked[j[inside], i[inside]]
    first = np.where(hit.any(axis=1), hit.argmax(axis=1), -1)
    return np.where(first >= 0, steps[np.maximum(first, 0)], np.inf), angles


def layered(static, layer):
    return inflate(layer.update_with_max(static), 0.05)


def test_the_obstacle_layer_marks_a_box_the_map_lacks_and_forgets_it_once_seen_through():
    grid = np.zeros((80, 120), np.int8)  # 6 m x 4 m, walls all round
    grid[:2, :] = grid[-2:, :] = grid[:, :2] = grid[:, -2:] = 100
    static = static_layer(grid)
    world = grid == 100
    with_box = world.copy()
    with_box[36:44, 70:76] = True  # a box 3.5..3.8 m east, 1.8..2.2 m north: not on the map
    robot = (1.5, 2.0)
    source = ObservationSource(obstacle_max_range=2.5, raytrace_max_range=3.0)
    layer = ObstacleLayer(static.shape, 0.05, (0.0, 0.0))

    def see(blocked):
        ranges, _angles = room_scan(blocked, robot)
        obs = observation_from_scan(ranges, -math.pi, 2 * math.pi / 360, 0.12, 8.0, (*robot, 0.0),
                                    source)  # fmt: skip
        layer.update([obs])
        layer.clear_footprint(*robot, 0.15)
        return layered(static, layer)

    seen = see(with_box)
    assert seen[40, 70] == LETHAL_OBSTACLE  # the box's face, 2.0 m ahead
    assert seen[40, 67] == INSCRIBED_INFLATED_OBSTACLE  # 0.15 m in front of it
    assert seen[40, 60] > 0  # inflated like any wall
    assert (seen[world] == LETHAL_OBSTACLE).all()  # the walls stay
    # Beyond obstacle_max_range nothing is marked: the east wall is 4.4 m away.
    assert layer.grid[40, 117] == NO_INFORMATION
    # The box is taken away: the beams now pass where it was and clear it.
    gone = see(world)
    assert gone[40, 70] == FREE_SPACE and (gone[36:44, 70:76] < INSCRIBED_INFLATED_OBSTACLE).all()
    assert np.array_equal(gone[30:50, 40:80], inflate(static, 0.05)[30:50, 40:80])
    assert (gone[world] == LETHAL_OBSTACLE).all()


def test_the_obstacle_layer_leaves_out_what_a_scan_cannot_vouch_for():
    static = static_layer(np.zeros((40, 40), np.int8))
    layer = ObstacleLayer(static.shape, 0.05, (0.0, 0.0))
    layer.grid[20, 30] = LETHAL_OBSTACLE  # something seen before, 0.5 m east of the robot
    source = ObservationSource()
    # inf (nothing within range_max), NaN and too-close readings are no observation: no clearing
    ranges = np.array([np.inf, np.nan, 0.05, np.inf])
    angles_min, step = -0.01, 0.005
    obs = observation_from_scan(ranges, angles_min, step, 0.12, 8.0, (1.0, 1.0, 0.0), source)
    layer.update([obs])
    assert layer.grid[20, 30] == LETHAL_OBSTACLE
    # ... unless inf_is_valid: then inf is a beam that saw nothing as far as it reaches
    free = ObservationSource(inf_is_valid=True)
    layer.update([observation_from_scan(ranges, angles_min, step, 0.12, 8.0, (1.0, 1.0, 0.0),
                                        free)])  # fmt: skip
    assert layer.grid[20, 30] == FREE_SPACE and layer.grid[20, 39] == FREE_SPACE
    # A lethal cell under the robot is freed by footprint clearing; one beside it is not.
    layer.grid[20, 20] = layer.grid[20, 25] = LETHAL_OBSTACLE
    layer.clear_footprint(1.0, 1.0, 0.15)
    assert layer.grid[20, 20] == FREE_SPACE and layer.grid[20, 25] == LETHAL_OBSTACLE
    layer.reset()
    assert (layer.grid == NO_INFORMATION).all()
