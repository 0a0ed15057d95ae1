"""The mapping node's log-odds update and Bresenham beams, on synthetic scans (no ROS)."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from nodes.common.occupancy_grid import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    LogOddsGrid,
    LogOddsModel,
    bresenham,
    cell_centres,
    log_odds,
    map_agreement,
    plan_distance,
    probability,
    ray_cells,
    scan_endpoints,
)


class _Box:
    def __init__(self, x, y, half_x, half_y, yaw=0.0):
        self.x, self.y, self.half_x, self.half_y, self.yaw = x, y, half_x, half_y, yaw


class _Circle:
    def __init__(self, x, y, radius):
        self.x, self.y, self.radius = x, y, radius


# A 4 m x 3 m room (inner faces x = +-2, y = +-1.5) with 0.1 m walls and a pillar.
ROOM = [
    _Box(2.05, 0.0, 0.05, 1.6),
    _Box(-2.05, 0.0, 0.05, 1.6),
    _Box(0.0, 1.55, 2.0, 0.05),
    _Box(0.0, -1.55, 2.0, 0.05),
    _Circle(1.0, 0.6, 0.2),
]


def synthetic_scan(x: float, y: float, yaw: float, count: int = 360, max_range: float = 8.0):
    """Exact ranges from (x, y, yaw) to the ROOM, by marching along each beam."""
    angles = -math.pi + np.arange(count) * (2 * math.pi / count)
    steps = np.arange(1, int(max_range / 0.002)) * 0.002
    ranges = []
    for angle in angles:
        px = x + steps * math.cos(yaw + angle)
        py = y + steps * math.sin(yaw + angle)
        inside = np.nonzero(plan_distance(ROOM, px, py) <= 0.0)[0]
        ranges.append(steps[inside[0]] if len(inside) else math.inf)
    return np.array(ranges), float(angles[0]), 2 * math.pi / count


def test_bresenham_visits_a_line_cell_by_cell_from_its_start():
    assert bresenham(0, 0, 5, 2) == [(0, 0), (1, 0), (2, 1), (3, 1), (4, 2), (5, 2)]
    assert bresenham(0, 0, -2, -5) == [(0, 0), (0, -1), (-1, -2), (-1, -3), (-2, -4), (-2, -5)]
    assert bresenham(3, 3, 3, 3) == [(3, 3)]
    assert bresenham(0, 0, 4, 4) == [(i, i) for i in range(5)]
    for cells in (bresenham(2, -1, -7, 4), bresenham(0, 0, 3, -11)):
        steps = {(b[0] - a[0], b[1] - a[1]) for a, b in zip(cells, cells[1:], strict=False)}
        assert all(max(abs(dx), abs(dy)) == 1 for dx, dy in steps)  # 8-connected, no gaps


def test_the_vectorised_beams_are_exactly_bresenhams_cells():
    rng = random.Random(7)
    lines = [tuple(rng.randint(-40, 40) for _ in range(4)) for _ in range(300)]
    lines += [(0, 0, 0, 0), (5, 5, 5, -5), (-3, 2, 9, 2)]
    x0, y0, x1, y1 = (np.array(v) for v in zip(*lines, strict=True))
    xs, ys, line, last = ray_cells(x0, y0, x1, y1)
    for index, (a, b, c, d) in enumerate(lines):
        mine = list(zip(xs[line == index].tolist(), ys[line == index].tolist(), strict=True))
        assert mine == bresenham(a, b, c, d), (a, b, c, d)
        assert last[line == index].tolist() == [False] * (len(mine) - 1) + [True]


def test_log_odds_and_probability_are_inverse():
    for p in (0.12, 0.4, 0.5, 0.7, 0.97):
        assert probability(log_odds(p)) == pytest.approx(p)
    assert log_odds(0.5) == 0.0


def test_one_beam_frees_the_cells_it_crosses_and_marks_the_cell_it_ends_in():
    model = LogOddsModel()
    grid = LogOddsGrid(0.1, model, initial_size=4.0)
    ends, hit = scan_endpoints([1.0], 0.0, 0.0, 0.1, 5.0, (0.05, 0.05, 0.0))
    grid.integrate((0.05, 0.05), ends, hit)
    i0, j0 = -grid.i0, -grid.j0  # the cell of the map point (0, 0)
    row = grid.cells[j0, i0 : i0 + 12]
    assert row[:10] == pytest.approx([model.miss] * 10)  # crossed: free evidence, once each
    assert row[10] == pytest.approx(model.hit)  # the beam ended at x = 1.05 (cell 10)
    assert row[11] == 0.0  # beyond the hit: untouched, unknown
    assert grid.cells.sum() == pytest.approx(10 * model.miss + model.hit)


def test_evidence_adds_up_and_is_clamped():
    model = LogOddsModel(hit=0.9, miss=-0.4, minimum=-2.0, maximum=3.5)
    grid = LogOddsGrid(0.1, model, initial_size=4.0)
    for _ in range(20):
        ends, hit = scan_endpoints([1.0], 0.0, 0.0, 0.1, 5.0, (0.05, 0.05, 0.0))
        grid.integrate((0.05, 0.05), ends, hit)
    i0, j0 = -grid.i0, -grid.j0
    assert grid.cells[j0, i0 + 10] == pytest.approx(3.5)  # 20 x 0.9, clamped
    assert grid.cells[j0, i0 + 5] == pytest.approx(-2.0)  # 20 x -0.4, clamped
    data = grid.occupancy().reshape(grid.height, grid.width)
    assert data[j0, i0 + 10] == OCCUPIED and data[j0, i0 + 5] == FREE
    assert data[j0, i0 + 11] == UNKNOWN and data[j0 + 3, i0] == UNKNOWN
    # The wall goes away: free evidence brings the cell back down, step by step.
    for _ in range(30):
        ends, hit = scan_endpoints([math.inf], 0.0, 0.0, 0.1, 1.5, (0.05, 0.05, 0.0))
        grid.integrate((0.05, 0.05), ends, hit)
    assert grid.cells[j0, i0 + 10] == pytest.approx(-2.0)
    assert grid.occupancy().reshape(grid.height, grid.width)[j0, i0 + 10] == FREE


def test_many_beams_through_one_cell_count_once_per_scan():
    model = LogOddsModel()
    grid = LogOddsGrid(0.05, model, initial_size=6.0)
    ranges = np.full(360, 2.0)
    ends, hit = scan_endpoints(ranges, -math.pi, math.pi / 180, 0.1, 5.0, (0.0, 0.0, 0.0))
    grid.integrate((0.0, 0.0), ends, hit)
    assert grid.cells.min() == pytest.approx(model.miss)  # the robot's cell: once, not 360 times
    assert grid.cells.max() == pytest.approx(model.hit)


def test_rep117_readings():
    ends, hit = scan_endpoints(
        [1.0, math.inf, -math.inf, math.nan, 0.05, 9.0], 0.0, 0.1, 0.1, 4.0, (0.0, 0.0, 0.0)
    )
    # 1.0: a hit; +inf and 9.0 (past range_max): free up to 4 m, no hit; -inf, NaN, 0.05: nothing
    assert hit.tolist() == [True, False, False]
    assert np.hypot(*ends.T).tolist() == pytest.approx([1.0, 4.0, 4.0])


def test_the_grid_grows_on_its_lattice_and_keeps_what_it_knew():
    grid = LogOddsGrid(0.05, initial_size=2.0, margin=1.0)
    assert grid.origin == pytest.approx((-1.0, -1.0)) and grid.width == 40
    ends, hit = scan_endpoints([0.5], 0.0, 0.0, 0.1, 8.0, (0.0, 0.0, 0.0))
    grid.integrate((0.0, 0.0), ends, hit)
    before = grid.occupancy().reshape(grid.height, grid.width)[20, 20:31].copy()
    ends, hit = scan_endpoints([3.0], 0.0, 0.0, 0.1, 8.0, (0.0, 0.0, math.pi))  # to x = -3
    grid.integrate((0.0, 0.0), ends, hit)
    x0, y0 = grid.origin
    assert x0 == pytest.approx(-4.0) and y0 == pytest.approx(-1.0)  # cell -60, then the margin
    assert round(x0 / 0.05) == pytest.approx(x0 / 0.05)  # still on the lattice
    after = grid.occupancy().reshape(grid.height, grid.width)
    column = round(-x0 / 0.05)
    assert after[20, column : column + 11].tolist() == before.tolist()
    assert after[20, column - 60] == OCCUPIED  # the new hit at x = -3.0 (cell -60)


def test_the_grid_never_grows_past_its_largest_size():
    grid = LogOddsGrid(0.1, initial_size=2.0, margin=0.5, max_size=4.0)
    ends, hit = scan_endpoints([10.0], 0.0, 0.0, 0.1, 20.0, (0.0, 0.0, 0.0))
    grid.integrate((0.0, 0.0), ends, hit)
    assert grid.width == 30 and grid.origin[0] == pytest.approx(-1.0)  # grew east to x = 2 only
    assert (grid.occupancy() == OCCUPIED).sum() == 0  # the hit lay outside: cut, no wall


def test_bad_parameters_are_refused_with_the_reason():
    with pytest.raises(ValueError, match="resolution"):
        LogOddsGrid(0.0)
    with pytest.raises(ValueError, match="log_odds_miss"):
        LogOddsGrid(0.05, LogOddsModel(miss=0.2))
    with pytest.raises(ValueError, match="free_thresh"):
        LogOddsGrid(0.05, LogOddsModel(free_thresh=0.7))


def test_a_synthetic_tour_maps_the_room_as_its_plan_says():
    grid = LogOddsGrid(0.05, initial_size=5.0)
    for x, y, yaw in ((0.0, 0.0, 0.0), (-1.2, -0.8, 1.0), (1.4, -0.9, 2.5), (-1.0, 0.9, -2.0)):
        ranges, angle_min, increment = synthetic_scan(x, y, yaw)
        ranges = ranges + np.random.default_rng(1).normal(0.0, 0.01, len(ranges))
        ends, hit = scan_endpoints(ranges, angle_min, increment, 0.12, 8.0, (x, y, yaw))
        for _ in range(3):
            grid.integrate((x, y), ends, hit)
    data = grid.occupancy()
    xs, ys = cell_centres(grid.origin, grid.resolution, grid.width, grid.height)
    result = map_agreement(data, plan_distance(ROOM, xs, ys), grid.resolution)
    assert result.percent >= 97.0, result.text()
    assert result.occupied > 200 and result.free > 2000, result.text()
    # A map that calls everything it saw free disagrees at the walls.
    wrong = np.where(data == OCCUPIED, FREE, data)
    assert map_agreement(wrong, plan_distance(ROOM, xs, ys), 0.05).percent < result.percent
