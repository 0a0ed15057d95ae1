"""The GridBased planner and the regulated pure pursuit controller, without ROS."""

from __future__ import annotations

import math

import numpy as np
import pytest
from nav2_controller.regulated_pure_pursuit import RPPParameters, compute_velocity
from nav2_costmap_2d import INSCRIBED_INFLATED_OBSTACLE
from nav2_costmap_2d.costmap_2d import costmap_from_grid
from nav2_planner.navfn_planner import PlannerOptions, create_plan, path_length
from nav2_planner.planner_exceptions import (
    GoalOccupied,
    NoValidPathCouldBeFound,
    StartOutsideMapBounds,
)

RES = 0.05


def room_with_a_block():
    """A 4 m x 3 m room, a 1 m x 2 m block in the middle from the south wall up."""
    grid = np.zeros((60, 80), np.int8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = 100
    grid[0:40, 30:50] = 100
    return costmap_from_grid(grid, RES, (0.0, 0.0))


@pytest.mark.parametrize("use_astar", [False, True])
def test_a_path_goes_around_the_block_and_never_through_inscribed_cells(use_astar):
    costmap = room_with_a_block()
    path = create_plan(
        costmap, (0.5, 0.5, 0.0), (3.5, 0.5, 0.0), PlannerOptions(use_astar=use_astar)
    )
    assert path[0][:2] == (0.5, 0.5) and path[-1][:2] == (3.5, 0.5)
    for x, y, _ in path[1:-1]:
        cell = costmap.world_to_map(x, y)
        assert cell is not None and costmap.get_cost(*cell) < INSCRIBED_INFLATED_OBSTACLE
    assert max(y for _x, y, _ in path) > 2.0  # over the block's top at y = 2 m
    # the shortest way around (up, over, down), give or take the inflation's margin
    shortest = 2 * math.hypot(1.0, 1.7) + 1.0
    assert shortest < path_length(path) < 1.3 * shortest


def test_bad_goals_get_nav2s_exceptions():
    costmap = room_with_a_block()
    with pytest.raises(StartOutsideMapBounds):
        create_plan(costmap, (-1.0, 0.5, 0.0), (3.5, 0.5, 0.0))
    with pytest.raises(GoalOccupied, match="lethal"):
        create_plan(costmap, (0.5, 0.5, 0.0), (2.0, 1.0, 0.0), PlannerOptions(tolerance=0.0))
    walled = costmap.copy()
    walled.costs[:, 60] = 254  # a wall from floor to ceiling east of the block
    with pytest.raises(NoValidPathCouldBeFound):
        create_plan(walled, (0.5, 0.5, 0.0), (3.5, 0.5, 0.0), PlannerOptions(tolerance=0.0))
    # with a tolerance, a goal in the block ends at the nearest reachable cell
    near = create_plan(costmap, (0.5, 0.5, 0.0), (1.6, 1.0, 0.0), PlannerOptions(tolerance=0.5))
    assert math.hypot(near[-1][0] - 1.6, near[-1][1] - 1.0) <= 0.5


def test_pure_pursuit_turns_towards_the_path():
    path = [(0.1 * i, 0.02 * i * i * 0.1, 0.0) for i in range(30)]  # bends to the left
    command = compute_velocity((0.0, 0.0, 0.0), path, (0.3, 0.0), RPPParameters())
    assert command.linear > 0 and command.angular > 0
    right = [(x, -y, 0.0) for x, y, _ in path]
    assert compute_velocity((0.0, 0.0, 0.0), right, (0.3, 0.0), RPPParameters()).angular < 0
    behind = [(-0.1 * i, 0.0, math.pi) for i in range(1, 20)]  # the path is behind: turn first
    turn = compute_velocity((0.0, 0.0, 0.0), behind, (0.0, 0.0), RPPParameters())
    assert turn.linear == 0.0 and turn.angular != 0.0
