"""The map as amcl uses it: cell states and the distance field of the likelihood model.

An OccupancyGrid's value 0 is free, 100 occupied (amcl, as Nav2's, takes
anything above 65 as occupied and 0..19 as free), the rest unknown. The
likelihood field needs, for every cell, the distance from its centre to the
nearest occupied cell's centre, capped at ``max_occ_dist``
(``laser_likelihood_max_dist``): computed exactly here, one axis at a time
(for each column the nearest obstacle in that column, then along each row
the best sum of squares), only as far as the cap reaches.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

FREE, UNKNOWN, OCCUPIED = -1, 0, 1  # amcl's own cell states (map_cell_t.occ_state)


def _shift(a: np.ndarray, k: int, axis: int, fill: float) -> np.ndarray:
    """``a`` moved by k cells along ``axis`` (out[i] = a[i + k]), ``fill`` where nothing is."""
    out = np.full_like(a, fill)
    n = a.shape[axis]
    if abs(k) >= n:
        return out
    src = [slice(None)] * a.ndim
    dst = [slice(None)] * a.ndim
    if k >= 0:
        src[axis], dst[axis] = slice(k, n), slice(0, n - k)
    else:
        src[axis], dst[axis] = slice(0, n + k), slice(-k, n)
    out[tuple(dst)] = a[tuple(src)]
    return out


def distance_field(occupied: np.ndarray, resolution: float, max_dist: float) -> np.ndarray:
    """Metres from each cell's centre to the nearest occupied cell's centre, at most max_dist."""
    reach = max(0, int(math.ceil(max_dist / resolution)))
    big = float(reach + 1) ** 2
    # Column pass: squared cell distance to the nearest obstacle in the same column.
    column = np.where(occupied, 0.0, big)
    for k in range(1, reach + 1):
        for sign in (1, -1):
            moved = _shift(occupied, sign * k, axis=0, fill=False)
            column = np.where(moved & (column > k * k), float(k * k), column)
    # Row pass: the best (row offset)^2 + column distance^2 within reach.
    best = column.copy()
    for k in range(1, reach + 1):
        for sign in (1, -1):
            best = np.minimum(best, _shift(column, sign * k, axis=1, fill=big) + k * k)
    return np.minimum(np.sqrt(best) * resolution, max_dist)


@dataclass
class AmclMap:
    """A grid of cell states in the map frame: cell (i, j) covers x in origin_x + [i, i+1) res."""

    states: np.ndarray  # (height, width) int8: FREE, UNKNOWN, OCCUPIED
    resolution: float
    origin_x: float
    origin_y: float
    max_occ_dist: float = 2.0
    distances: np.ndarray | None = None  # filled by update_cspace

    @classmethod
    def from_occupancy(
        cls,
        data: Sequence[int] | np.ndarray,
        width: int,
        height: int,
        resolution: float,
        origin: tuple[float, float],
    ) -> AmclMap:
        """From an OccupancyGrid's data (row-major, the row at the origin first).

        ValueError when the grid cannot be a map (no cells, a data length that
        does not match, a resolution that is not a positive number).
        """
        if width <= 0 or height <= 0:
            raise ValueError(f"the map has no cells ({width} x {height})")
        if not (math.isfinite(resolution) and resolution > 0.0):
            raise ValueError(f"the map's resolution must be a positive number, not {resolution}")
        if not all(math.isfinite(v) for v in origin):
            raise ValueError(f"the map's origin is not a point: {origin}")
        flat = np.asarray(data, dtype=np.int16).reshape(-1)
        if flat.size != width * height:
            raise ValueError(f"the map has {flat.size} cells for {width} x {height}")
        values: np.ndarray = flat.reshape(height, width)
        states = np.full((height, width), UNKNOWN, np.int8)
        states[values == 0] = FREE
        states[values == 100] = OCCUPIED
        # Nav2 also reads values between as probabilities: above 65 occupied, below 20 free.
        states[(values > 65) & (values < 100)] = OCCUPIED
        states[(values > 0) & (values < 20)] = FREE
        return cls(states, float(resolution), float(origin[0]), float(origin[1]))

    @property
    def width(self) -> int:
        return int(self.states.shape[1])

    @property
    def height(self) -> int:
        return int(self.states.shape[0])

    def update_cspace(self, max_occ_dist: float) -> None:
        """Compute the distance field up to ``max_occ_dist`` metres."""
        self.max_occ_dist = float(max_occ_dist)
        self.distances = distance_field(
            self.states == OCCUPIED, self.resolution, self.max_occ_dist
        ).astype(np.float32)

    def cells(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(i, j, inside) of map-frame points."""
        i = np.floor((np.asarray(x) - self.origin_x) / self.resolution).astype(np.int64)
        j = np.floor((np.asarray(y) - self.origin_y) / self.resolution).astype(np.int64)
        inside = (i >= 0) & (i < self.width) & (j >= 0) & (j < self.height)
        return i, j, inside

    def state_at(self, x: float, y: float) -> int:
        """The state of the cell holding a point (UNKNOWN off the map)."""
        i, j, inside = self.cells(np.array([x]), np.array([y]))
        return int(self.states[j[0], i[0]]) if inside[0] else UNKNOWN

    def free_cells(self) -> np.ndarray:
        """Flat indices (j * width + i) of the free cells: where a lost robot may be."""
        return np.flatnonzero(self.states.reshape(-1) == FREE)

    def cell_centres(self, flat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        j, i = np.divmod(np.asarray(flat, np.int64), self.width)
        return (
            self.origin_x + (i + 0.5) * self.resolution,
            self.origin_y + (j + 0.5) * self.resolution,
        )
