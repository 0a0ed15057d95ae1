"""GridBased: a grid planner over a Nav2 costmap, in the manner of NavFn.

NavFn, the planner Nav2's default configuration loads as ``GridBased``,
spreads a potential from the goal over the costmap (Dijkstra, or A* with
``use_astar``) and follows it down to the start. This planner searches the
same cost field with Dijkstra or A* on the 8-connected grid and returns the
cheapest chain of cells:

- a cell's step cost is ``COST_NEUTRAL + COST_FACTOR * cost`` (NavFn's 50 and
  0.8) times the step length, so the path keeps away from walls where the
  inflation makes cells dear; inscribed (253) and lethal (254) cells are
  walls; unknown (255) cells are passable at the highest cost when
  ``allow_unknown`` (else walls);
- A* adds the straight-line distance to the goal at the neutral cost (never
  more than the true cost: the path stays the cheapest);
- as NavFn, the start cell is cleared (the robot is there), and a robot
  that stands in inscribed space may drive out through it;
- ``tolerance`` (m): when the goal itself cannot be reached, the reachable
  cell nearest to it within that distance ends the path.

Failures raise the exceptions of :mod:`nav2_planner.planner_exceptions`
with NavFn's messages. No ROS here: testable alone.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from nav2_costmap_2d.cost_values import (
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    MAX_NON_OBSTACLE,
    NO_INFORMATION,
)
from nav2_costmap_2d.costmap_2d import Costmap2D

from nav2_planner.planner_exceptions import (
    GoalOccupied,
    GoalOutsideMapBounds,
    NoValidPathCouldBeFound,
    PlannerCancelled,
    StartOutsideMapBounds,
)

COST_NEUTRAL = 50.0
COST_FACTOR = 0.8
SQRT2 = math.sqrt(2.0)
Pose2D = tuple[float, float, float]  # x, y, yaw


@dataclass(frozen=True)
class PlannerOptions:
    tolerance: float = 0.5  # m (NavFn's default)
    use_astar: bool = False
    allow_unknown: bool = True


def step_costs(costmap: Costmap2D, allow_unknown: bool) -> np.ndarray:
    """Cost of entering each cell per cell length; inf for a wall."""
    costs = costmap.costs.astype(np.float64)
    weight = COST_NEUTRAL + COST_FACTOR * costs
    blocked = costmap.costs >= INSCRIBED_INFLATED_OBSTACLE
    if allow_unknown:
        unknown = costmap.costs == NO_INFORMATION
        weight[unknown] = COST_NEUTRAL + COST_FACTOR * MAX_NON_OBSTACLE
        blocked &= ~unknown
    weight[blocked] = math.inf
    return weight


def _inscribed_region(costmap: Costmap2D, start: tuple[int, int]) -> set[int]:
    """The inscribed cells the robot stands in, connected to its cell (it may drive out)."""
    w, h = costmap.size_x, costmap.size_y
    grid = costmap.costs
    seen = {start[1] * w + start[0]}
    todo = [start]
    while todo and len(seen) < 4000:
        x, y = todo.pop()
        for nx, ny in ((x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)):
            if 0 <= nx < w and 0 <= ny < h and grid[ny, nx] == INSCRIBED_INFLATED_OBSTACLE:
                i = ny * w + nx
                if i not in seen:
                    seen.add(i)
                    todo.append((nx, ny))
    return seen


def search(
    weight: np.ndarray,
    start: tuple[int, int],
    goal: tuple[int, int] | None,
    use_astar: bool,
    cancel_checker: Callable[[], bool] | None = None,
) -> tuple[dict[int, int], dict[int, float]]:
    """Dijkstra / A* from ``start``; stops at ``goal`` (None: spread over everything reachable).

    Returns (came_from, cost so far) keyed by flat cell index ``y * width + x``.
    """
    h, w = weight.shape
    cell_cost = weight.ravel().tolist()
    s = start[1] * w + start[0]
    g = None if goal is None else goal[1] * w + goal[0]
    gx, gy = goal if goal is not None else (0, 0)
    astar = use_astar and goal is not None
    best: dict[int, float] = {s: 0.0}
    came_from: dict[int, int] = {s: s}
    heap: list[tuple[float, float, int]] = [(0.0, 0.0, s)]
    closed: set[int] = set()
    moves = (
        (1, 0, 1.0),
        (-1, 0, 1.0),
        (0, 1, 1.0),
        (0, -1, 1.0),
        (1, 1, SQRT2),
        (1, -1, SQRT2),
        (-1, 1, SQRT2),
        (-1, -1, SQRT2),
    )
    popped = 0
    while heap:
        _f, cost, i = heapq.heappop(heap)
        if i in closed:
            continue
        closed.add(i)
        if i == g:
            break
        popped += 1
        if cancel_checker is not None and popped % 4096 == 0 and cancel_checker():
            raise PlannerCancelled("planning was cancelled")
        y, x = divmod(i, w)
        for dx, dy, length in moves:
            nx, ny = x + dx, y + dy
            if nx < 0 or ny < 0 or nx >= w or ny >= h:
                continue
            n = ny * w + nx
            c = cell_cost[n]
            if c == math.inf:
                continue
            if (
                dx
                and dy
                and (cell_cost[y * w + nx] == math.inf or cell_cost[ny * w + x] == math.inf)
            ):
                continue  # no squeezing diagonally between two walls
            new = cost + length * c
            if new < best.get(n, math.inf):
                best[n] = new
                came_from[n] = i
                f = new
                if astar:
                    f += COST_NEUTRAL * math.hypot(nx - gx, ny - gy)
                heapq.heappush(heap, (f, new, n))
    return came_from, best


def _trace(came_from: dict[int, int], end: int, width: int) -> list[tuple[int, int]]:
    cells = []
    i = end
    while True:
        y, x = divmod(i, width)
        cells.append((x, y))
        parent = came_from[i]
        if parent == i:
            break
        i = parent
    cells.reverse()
    return cells


def _yaw_along(points: list[tuple[float, float]], i: int) -> float:
    a = points[max(i - 1, 0)] if i == len(points) - 1 else points[i]
    b = points[i] if i == len(points) - 1 else points[i + 1]
    return math.atan2(b[1] - a[1], b[0] - a[0])


def create_plan(
    costmap: Costmap2D,
    start: Pose2D,
    goal: Pose2D,
    options: PlannerOptions | None = None,
    cancel_checker: Callable[[], bool] | None = None,
) -> list[Pose2D]:
    """The path (x, y, yaw) from ``start`` to ``goal`` over ``costmap`` (``createPlan``)."""
    opts = options or PlannerOptions()
    start_cell = costmap.world_to_map(start[0], start[1])
    if start_cell is None:
        raise StartOutsideMapBounds(
            f"Start Coordinates of({start[0]:f}, {start[1]:f}) was outside bounds"
        )
    goal_cell = costmap.world_to_map(goal[0], goal[1])
    if goal_cell is None:
        raise GoalOutsideMapBounds(
            f"Goal Coordinates of({goal[0]:f}, {goal[1]:f}) was outside bounds"
        )
    if opts.tolerance == 0 and costmap.get_cost(*goal_cell) == LETHAL_OBSTACLE:
        raise GoalOccupied(f"Goal Coordinates of({goal[0]:f}, {goal[1]:f}) was in lethal cost")
    if start[0] == goal[0] and start[1] == goal[1]:
        return [(goal[0], goal[1], goal[2])]

    weight = step_costs(costmap, opts.allow_unknown)
    w = costmap.size_x
    sx, sy = start_cell
    if costmap.get_cost(sx, sy) == INSCRIBED_INFLATED_OBSTACLE:
        flat = weight.ravel()
        for i in _inscribed_region(costmap, start_cell):
            flat[i] = COST_NEUTRAL + COST_FACTOR * INSCRIBED_INFLATED_OBSTACLE
    weight[sy, sx] = COST_NEUTRAL  # clearRobotCell

    end: int | None = None
    goal_index = goal_cell[1] * w + goal_cell[0]
    if weight[goal_cell[1], goal_cell[0]] != math.inf:
        came_from, _best = search(weight, start_cell, goal_cell, opts.use_astar, cancel_checker)
        if goal_index in came_from:
            end = goal_index
    else:
        came_from = {}
    if end is None and opts.tolerance > 0:
        if not came_from or goal_index not in came_from:
            came_from, _best = search(weight, start_cell, None, False, cancel_checker)
        end = _nearest_reached(costmap, came_from, goal, opts.tolerance)
    if end is None:
        raise NoValidPathCouldBeFound(
            f"Failed to create plan with tolerance of: {opts.tolerance:f}"
        )
    cells = _trace(came_from, end, w)
    points = [costmap.map_to_world(x, y) for x, y in cells]
    points[0] = (start[0], start[1])
    if end == goal_index:
        points[-1] = (goal[0], goal[1])
    if len(points) == 1:
        return [(points[0][0], points[0][1], goal[2])]
    path = [(p[0], p[1], _yaw_along(points, i)) for i, p in enumerate(points)]
    path[-1] = (path[-1][0], path[-1][1], goal[2])
    return path


def _nearest_reached(
    costmap: Costmap2D, came_from: dict[int, int], goal: Pose2D, tolerance: float
) -> int | None:
    w = costmap.size_x
    best, best_d = None, math.inf
    reach = int(math.ceil(tolerance / costmap.resolution))
    cell = costmap.world_to_map(goal[0], goal[1])
    assert cell is not None
    for y in range(max(cell[1] - reach, 0), min(cell[1] + reach + 1, costmap.size_y)):
        for x in range(max(cell[0] - reach, 0), min(cell[0] + reach + 1, w)):
            i = y * w + x
            if i not in came_from:
                continue
            cx, cy = costmap.map_to_world(x, y)
            d = math.hypot(cx - goal[0], cy - goal[1])
            if d <= tolerance and d < best_d:
                best, best_d = i, d
    return best


def path_length(path: list[Pose2D]) -> float:
    return sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(path, path[1:], strict=False))
