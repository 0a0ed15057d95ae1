"""Occupancy grid mapping with known poses: the log-odds update the textbooks teach.

A map cell is occupied with some probability p; the grid keeps its log-odds
``l = log(p / (1 - p))`` instead, because then evidence adds up: each scan adds
``log_odds_hit`` to the cell a beam ends in and ``log_odds_miss`` (negative) to
every cell the beam crossed on its way there (the inverse sensor model), and
the sum is clamped to ``[log_odds_min, log_odds_max]`` so that a cell can
change its mind when the world changes. A cell never crossed stays at 0
(p = 0.5: unknown). Within one scan a cell is updated once: occupied if a
beam ends in it, else free if a beam crossed it (Thrun, Burgard and Fox,
*Probabilistic Robotics*, table 9.1).

The cells a beam crosses are found with Bresenham's line algorithm
(``bresenham`` is the step-by-step version; ``ray_cells`` computes the same
cells for many beams at once with numpy, as the mapping node needs 360 beams
ten times a second).

The map a node publishes (nav_msgs/OccupancyGrid) is trinary here: -1
unknown, 0 free (p below ``free_thresh``), 100 occupied (p above
``occupied_thresh``); row-major from the cell at ``origin``, x first.

``plan_distance`` and ``map_agreement`` compare such a map with a world's
floor plan (the simulation's walls and furniture): how many of the cells
the map claims to know agree with the plan. No ROS here.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

UNKNOWN, FREE, OCCUPIED = -1, 0, 100


def log_odds(p: float) -> float:
    return math.log(p / (1.0 - p))


def probability(l_value: float | np.ndarray) -> float | np.ndarray:
    return 1.0 - 1.0 / (1.0 + np.exp(l_value))


@dataclass(frozen=True)
class LogOddsModel:
    """The inverse sensor model and the thresholds that turn log-odds into -1/0/100."""

    hit: float = log_odds(0.7)  # 0.85: a beam ended in the cell
    miss: float = log_odds(0.4)  # -0.41: a beam crossed the cell
    minimum: float = log_odds(0.12)  # -1.99: clamp, so that a cell can change its mind
    maximum: float = log_odds(0.97)  # 3.48
    occupied_thresh: float = 0.65  # p above: 100
    free_thresh: float = 0.25  # p below: 0

    def check(self) -> str:
        """Why these values cannot work ('' when they can)."""
        if not all(math.isfinite(v) for v in (self.hit, self.miss, self.minimum, self.maximum)):
            return "log-odds must be finite numbers"
        if self.hit <= 0.0:
            return f"log_odds_hit must be > 0 (a hit is evidence of an obstacle), got {self.hit}"
        if self.miss >= 0.0:
            return f"log_odds_miss must be < 0 (a pass is evidence of free space), got {self.miss}"
        if not self.minimum < 0.0 < self.maximum:
            return f"need log_odds_min < 0 < log_odds_max, got {self.minimum}, {self.maximum}"
        if not 0.0 < self.free_thresh < self.occupied_thresh < 1.0:
            return (
                "need 0 < free_thresh < occupied_thresh < 1, got "
                f"{self.free_thresh}, {self.occupied_thresh}"
            )
        return ""


# ------------------------------------------------------------------ Bresenham


def bresenham(x0: int, y0: int, x1: int, y1: int) -> list[tuple[int, int]]:
    """The cells of the line from (x0, y0) to (x1, y1), both included, from the start.

    Integer arithmetic only: step along the longer axis one cell at a time;
    ``error`` says when the line has drifted half a cell along the other axis.
    """
    dx, dy = abs(x1 - x0), abs(y1 - y0)
    sx, sy = (1 if x1 >= x0 else -1), (1 if y1 >= y0 else -1)
    steep = dy > dx
    major, minor = (dy, dx) if steep else (dx, dy)
    error = 2 * minor - major
    along = across = 0
    cells = []
    for _ in range(major + 1):
        if steep:
            cells.append((x0 + sx * across, y0 + sy * along))
        else:
            cells.append((x0 + sx * along, y0 + sy * across))
        if error > 0:
            across += 1
            error -= 2 * major
        error += 2 * minor
        along += 1
    return cells


def ray_cells(
    x0: np.ndarray, y0: np.ndarray, x1: np.ndarray, y1: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``bresenham`` for many lines at once.

    Returns (x, y, line, last): every cell of every line as parallel arrays,
    which line it belongs to, and whether it is that line's last cell.
    The k-th step along the longer axis moves ``floor((2 k minor + major - 1)
    / (2 major))`` cells along the other: exactly the cells ``bresenham``
    visits (tests/nav/test_occupancy_grid.py compares them).
    """
    x0, y0 = np.asarray(x0, np.int64), np.asarray(y0, np.int64)
    x1, y1 = np.asarray(x1, np.int64), np.asarray(y1, np.int64)
    dx, dy = np.abs(x1 - x0), np.abs(y1 - y0)
    sx, sy = np.where(x1 >= x0, 1, -1), np.where(y1 >= y0, 1, -1)
    steep = dy > dx
    major, minor = np.where(steep, dy, dx), np.where(steep, dx, dy)
    if len(major) == 0:
        empty = np.zeros(0, np.int64)
        return empty, empty, empty, np.zeros(0, bool)
    k = np.arange(int(major.max()) + 1)[None, :]
    inside = k <= major[:, None]
    safe = np.maximum(major, 1)[:, None]
    across = (2 * k * minor[:, None] + safe - 1) // (2 * safe)
    along = k
    step_x = np.where(steep[:, None], across, along)
    step_y = np.where(steep[:, None], along, across)
    xs = (x0[:, None] + sx[:, None] * step_x)[inside]
    ys = (y0[:, None] + sy[:, None] * step_y)[inside]
    line = np.broadcast_to(np.arange(len(major))[:, None], inside.shape)[inside]
    last = (k == major[:, None])[inside]
    return xs, ys, line, last


# ------------------------------------------------------------------ scans


def scan_endpoints(
    ranges: Sequence[float] | np.ndarray,
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    sensor: tuple[float, float, float],
) -> tuple[np.ndarray, np.ndarray]:
    """Where each beam ends in the map (N, 2) and whether it hit something (N,).

    ``sensor`` is the scanner's (x, y, yaw) in the map. REP 117: a beam that
    saw nothing (``+inf``, or a value past ``range_max``) clears space up to
    ``range_max`` and hits nothing; ``-inf``, NaN and readings under
    ``range_min`` say nothing and are left out.
    """
    r = np.asarray(ranges, dtype=np.float64)
    angles = angle_min + np.arange(len(r)) * angle_increment
    hit = np.isfinite(r) & (r >= range_min) & (r <= range_max)
    nothing = (np.isposinf(r) | (np.isfinite(r) & (r > range_max))) & (range_max > 0)
    keep = hit | nothing
    length = np.where(hit, r, range_max)[keep]
    x, y, yaw = sensor
    theta = yaw + angles[keep]
    ends = np.stack([x + length * np.cos(theta), y + length * np.sin(theta)], axis=1)
    return ends, hit[keep]


# ------------------------------------------------------------------ the grid


class LogOddsGrid:
    """A growing grid of log-odds, 0 everywhere at first (unknown).

    Cell (i, j) covers ``[i, i+1) * resolution`` in x and ``[j, j+1) *
    resolution`` in y of the map frame: the lattice is fixed, so growing never
    moves a cell; the grid only gains rows and columns, ``margin`` metres at a
    time beyond what it must cover, and never beyond ``max_size`` metres
    around where it started (beams reaching past that are cut at the edge and
    count as hitting nothing).
    """

    def __init__(
        self,
        resolution: float = 0.05,
        model: LogOddsModel | None = None,
        *,
        center: tuple[float, float] = (0.0, 0.0),
        initial_size: float = 10.0,
        margin: float = 2.0,
        max_size: float = 60.0,
    ) -> None:
        if not (math.isfinite(resolution) and resolution > 0.0):
            raise ValueError(f"resolution must be a positive number of metres, got {resolution}")
        self.resolution = float(resolution)
        self.model = model or LogOddsModel()
        problem = self.model.check()
        if problem:
            raise ValueError(problem)
        self.margin = max(0.0, margin)
        half_max = max(max_size, resolution) / 2.0
        cx, cy = center
        self.limit = (  # the cells the grid may ever cover: [i_min, i_max) x [j_min, j_max)
            math.floor((cx - half_max) / resolution),
            math.floor((cy - half_max) / resolution),
            math.ceil((cx + half_max) / resolution),
            math.ceil((cy + half_max) / resolution),
        )
        half = min(initial_size, max_size) / 2.0
        self.i0, self.j0 = (
            self._clamp_i(math.floor((cx - half) / resolution)),
            self._clamp_j(math.floor((cy - half) / resolution)),
        )
        i1 = self._clamp_i(math.ceil((cx + half) / resolution))
        j1 = self._clamp_j(math.ceil((cy + half) / resolution))
        self.cells = np.zeros((max(j1 - self.j0, 1), max(i1 - self.i0, 1)), np.float32)
        self.updates = 0  # scans integrated

    # --- geometry ---
    @property
    def width(self) -> int:
        return int(self.cells.shape[1])

    @property
    def height(self) -> int:
        return int(self.cells.shape[0])

    @property
    def origin(self) -> tuple[float, float]:
        """The map-frame position of the corner of cell (0, 0)."""
        return self.i0 * self.resolution, self.j0 * self.resolution

    def _clamp_i(self, i: int) -> int:
        return min(max(i, self.limit[0]), self.limit[2])

    def _clamp_j(self, j: int) -> int:
        return min(max(j, self.limit[1]), self.limit[3])

    def lattice(self, points: np.ndarray) -> np.ndarray:
        """The fixed-lattice cell (i, j) of map-frame points (N, 2)."""
        return np.floor(np.asarray(points, np.float64) / self.resolution).astype(np.int64)

    def grow_to(self, low: tuple[int, int], high: tuple[int, int]) -> bool:
        """Cover lattice cells low..high (inclusive) plus the margin, within the limit."""
        i_lo, j_lo = low
        i_hi, j_hi = high
        i1, j1 = self.i0 + self.width, self.j0 + self.height
        if i_lo >= self.i0 and j_lo >= self.j0 and i_hi < i1 and j_hi < j1:
            return False
        pad = int(math.ceil(self.margin / self.resolution))
        new_i0 = self._clamp_i(min(self.i0, i_lo - pad if i_lo < self.i0 else self.i0))
        new_j0 = self._clamp_j(min(self.j0, j_lo - pad if j_lo < self.j0 else self.j0))
        new_i1 = self._clamp_i(max(i1, i_hi + 1 + pad if i_hi >= i1 else i1))
        new_j1 = self._clamp_j(max(j1, j_hi + 1 + pad if j_hi >= j1 else j1))
        if (new_i0, new_j0, new_i1, new_j1) == (self.i0, self.j0, i1, j1):
            return False
        grown = np.zeros((new_j1 - new_j0, new_i1 - new_i0), np.float32)
        dj, di = self.j0 - new_j0, self.i0 - new_i0
        grown[dj : dj + self.height, di : di + self.width] = self.cells
        self.cells, self.i0, self.j0 = grown, new_i0, new_j0
        return True

    # --- the update ---
    def integrate(self, sensor_xy: tuple[float, float], ends: np.ndarray, hit: np.ndarray) -> None:
        """One scan: the beams from ``sensor_xy`` to ``ends`` (N, 2), ``hit`` (N,) where they
        hit something. Each cell changes once: occupied wins over free."""
        ends = np.asarray(ends, np.float64).reshape(-1, 2)
        hit = np.asarray(hit, bool).reshape(-1)
        start = self.lattice(np.array([sensor_xy]))[0]
        cells = self.lattice(ends)
        if len(cells):
            low = np.minimum(cells.min(axis=0), start)
            high = np.maximum(cells.max(axis=0), start)
            self.grow_to((int(low[0]), int(low[1])), (int(high[0]), int(high[1])))
        lo_i, lo_j, hi_i, hi_j = self.limit
        outside = (
            (cells[:, 0] < lo_i)
            | (cells[:, 0] >= hi_i)
            | (cells[:, 1] < lo_j)
            | (cells[:, 1] >= hi_j)
        )
        if outside.any():  # past the largest map allowed: cut at the edge, no hit there
            cells[:, 0] = np.clip(cells[:, 0], lo_i, hi_i - 1)
            cells[:, 1] = np.clip(cells[:, 1], lo_j, hi_j - 1)
            hit = hit & ~outside
        n = len(cells)
        xs, ys, line, last = ray_cells(
            np.full(n, start[0]), np.full(n, start[1]), cells[:, 0], cells[:, 1]
        )
        xs, ys = xs - self.i0, ys - self.j0
        valid = (xs >= 0) & (xs < self.width) & (ys >= 0) & (ys < self.height)
        flat = ys * self.width + xs
        ending = last & hit[line]
        occupied = np.unique(flat[valid & ending])
        free = np.setdiff1d(np.unique(flat[valid & ~ending]), occupied, assume_unique=True)
        grid = self.cells.reshape(-1)
        model = self.model
        grid[free] = np.clip(grid[free] + model.miss, model.minimum, model.maximum)
        grid[occupied] = np.clip(grid[occupied] + model.hit, model.minimum, model.maximum)
        self.updates += 1

    # --- what a map message carries ---
    def occupancy(self) -> np.ndarray:
        """-1/0/100 per cell, row-major (y rows, x columns) as OccupancyGrid.data."""
        m = self.model
        data = np.full(self.cells.shape, UNKNOWN, np.int8)
        data[self.cells > log_odds(m.occupied_thresh)] = OCCUPIED
        data[self.cells < log_odds(m.free_thresh)] = FREE
        return data.reshape(-1)

    def probabilities(self) -> np.ndarray:
        return np.asarray(probability(self.cells), np.float32)


# ------------------------------------------------------------------ agreement with a plan


def cell_centres(
    origin: tuple[float, float], resolution: float, width: int, height: int
) -> tuple[np.ndarray, np.ndarray]:
    """x, y of each cell's centre, (height, width) arrays (an unturned map)."""
    xs = origin[0] + (np.arange(width) + 0.5) * resolution
    ys = origin[1] + (np.arange(height) + 0.5) * resolution
    return np.meshgrid(xs, ys)


def plan_distance(obstacles: Iterable[Any], xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Signed distance from each point to the nearest obstacle of a floor plan (< 0 inside).

    ``obstacles`` are the shapes ``app.lessons.checks._world_map`` reads from a
    world file: circles (``x, y, radius``) and rectangles turned about z
    (``x, y, half_x, half_y, yaw``).
    """
    best = np.full(np.shape(xs), np.inf)
    for shape in obstacles:
        dx, dy = xs - shape.x, ys - shape.y
        if hasattr(shape, "radius"):
            d = np.hypot(dx, dy) - shape.radius
        else:
            c, s = math.cos(shape.yaw), math.sin(shape.yaw)
            qx = np.abs(c * dx + s * dy) - shape.half_x
            qy = np.abs(-s * dx + c * dy) - shape.half_y
            outside = np.hypot(np.maximum(qx, 0.0), np.maximum(qy, 0.0))
            d = outside + np.minimum(np.maximum(qx, qy), 0.0)
        best = np.minimum(best, d)
    return best


@dataclass(frozen=True)
class Agreement:
    """How a map's known cells compare with the plan."""

    known: int
    agree: int
    occupied: int
    occupied_agree: int
    free: int
    free_agree: int

    @property
    def percent(self) -> float:
        return 100.0 * self.agree / self.known if self.known else math.nan

    def text(self) -> str:
        return (
            f"{self.percent:.1f} % of {self.known} known cells agree with the plan "
            f"(occupied {self.occupied_agree}/{self.occupied}, free {self.free_agree}/{self.free})"
        )


def map_agreement(
    data: Sequence[int] | np.ndarray, distance: np.ndarray, resolution: float
) -> Agreement:
    """Compare a -1/0/100 map with the plan's signed distances at its cell centres.

    An occupied cell agrees when an obstacle reaches into it (one is within
    half a cell diagonal of its centre); a free cell agrees when its centre is
    not inside an obstacle. Unknown cells are not counted; values between 0
    and 100 count as occupied from 50 up.
    """
    values = np.asarray(data, np.int16).reshape(np.shape(distance))
    occupied = values >= 50
    free = (values >= 0) & (values < 50)
    near = distance <= resolution * math.sqrt(0.5)
    clear = distance > 0.0
    occupied_agree = int((occupied & near).sum())
    free_agree = int((free & clear).sum())
    return Agreement(
        known=int(occupied.sum() + free.sum()),
        agree=occupied_agree + free_agree,
        occupied=int(occupied.sum()),
        occupied_agree=occupied_agree,
        free=int(free.sum()),
        free_agree=free_agree,
    )


def floor_points(
    obstacles: Sequence[Any],
    start: tuple[float, float] = (0.0, 0.0),
    spacing: float = 0.05,
    clearance: float = 0.1,
) -> tuple[np.ndarray, np.ndarray]:
    """x, y of the floor a robot starting at ``start`` can reach, on a lattice of ``spacing``.

    The floor is every lattice point at least ``clearance`` from any obstacle
    and joined to ``start`` through such points (rooms behind a closed wall,
    or the outside of the building, are not floor).
    """
    import cv2  # the connected regions of a picture, as OpenCV finds them

    extent = [(o.x, o.y, getattr(o, "radius", 0.0) + getattr(o, "half_x", 0.0)
               + getattr(o, "half_y", 0.0)) for o in obstacles]  # fmt: skip
    low_x = min(x - r for x, _y, r in extent)
    high_x = max(x + r for x, _y, r in extent)
    low_y = min(y - r for _x, y, r in extent)
    high_y = max(y + r for _x, y, r in extent)
    xs, ys = np.meshgrid(np.arange(low_x, high_x, spacing), np.arange(low_y, high_y, spacing))
    open_floor = (plan_distance(obstacles, xs, ys) >= clearance).astype(np.uint8)
    _count, labels = cv2.connectedComponents(open_floor, connectivity=4)
    row, col = np.unravel_index(np.argmin(np.hypot(xs - start[0], ys - start[1])), xs.shape)
    if not open_floor[row, col]:
        return np.empty(0), np.empty(0)
    reachable = labels == labels[row, col]
    return xs[reachable], ys[reachable]


def map_values_at(
    data: Sequence[int] | np.ndarray,
    origin: tuple[float, float],
    resolution: float,
    width: int,
    height: int,
    xs: np.ndarray,
    ys: np.ndarray,
) -> np.ndarray:
    """The map's value (-1, 0..100) at each point; -1 where the (unturned) map does not reach."""
    grid = np.asarray(data, np.int16).reshape(height, width)
    cols = np.floor((xs - origin[0]) / resolution).astype(np.int64)
    rows = np.floor((ys - origin[1]) / resolution).astype(np.int64)
    inside = (cols >= 0) & (cols < width) & (rows >= 0) & (rows < height)
    values = np.full(np.shape(xs), UNKNOWN, np.int16)
    values[inside] = grid[rows[inside], cols[inside]]
    return values


def floor_coverage(values_at_floor: np.ndarray) -> float:
    """Per cent of the floor's points the map calls free (0..49)."""
    if values_at_floor.size == 0:
        return math.nan
    free = (values_at_floor >= 0) & (values_at_floor < 50)
    return 100.0 * float(free.sum()) / values_at_floor.size
