"""Nav2's obstacle layer in numpy: obstacles seen by a laser scanner, cleared by raytracing.

The layer keeps a grid of its own, the size of the costmap, every cell
NO_INFORMATION at first (``track_unknown_space``; else FREE). Each update,
as Nav2's ``ObstacleLayer::updateBounds`` does with its latest observations:

1. *clearing*: along every beam that hit something, from ``raytrace_min_range``
   up to the end point (at most ``raytrace_max_range`` from the sensor), the
   cells the beam crossed become FREE; the end point's own cell is left alone.
   So an obstacle that went away is forgotten once a beam passes through
   where it was;
2. *marking*: the cell of every end point between ``obstacle_min_range`` and
   ``obstacle_max_range`` from the sensor becomes LETHAL;
3. *footprint clearing*: the cells under the robot become FREE (the robot
   cannot stand in an obstacle; ``footprint_clearing_enabled``).

Readings outside the scanner's ``range_min``..``range_max`` and NaNs are no
observation at all (laser_geometry drops them before Nav2 sees them), unless
``inf_is_valid``: then ``+inf`` is a beam that saw nothing up to ``range_max``,
which clears but does not mark.

The layer goes into the costmap as Nav2's ``updateWithMax``: a cell the layer
knows (not NO_INFORMATION) takes the layer's cost where the costmap's is
unknown or lower. Walls the static map already has stay lethal; a box on the
floor that the map does not have becomes lethal, and inflation then spreads
around it like around any wall.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from nav2_costmap_2d.cost_values import FREE_SPACE, LETHAL_OBSTACLE, NO_INFORMATION


@dataclass
class ObservationSource:
    """One ``observation_sources`` entry (a LaserScan topic) and its ranges (Nav2's defaults)."""

    name: str = "scan"
    topic: str = "/scan"
    marking: bool = True
    clearing: bool = True
    obstacle_max_range: float = 2.5
    obstacle_min_range: float = 0.0
    raytrace_max_range: float = 3.0
    raytrace_min_range: float = 0.0
    inf_is_valid: bool = False


@dataclass
class Observation:
    """A scan turned into the costmap's frame: the sensor's origin and each beam's end point."""

    origin: tuple[float, float]
    ends_x: np.ndarray  # m, in the costmap's frame
    ends_y: np.ndarray
    ranges: np.ndarray  # m from the origin
    hit: np.ndarray  # bool: the beam ended on something (False: inf_is_valid's range_max)
    source: ObservationSource


def observation_from_scan(
    ranges: np.ndarray,
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    sensor_pose: tuple[float, float, float],
    source: ObservationSource,
) -> Observation:
    """A LaserScan's readings, with the scanner at ``sensor_pose`` (x, y, yaw) in the costmap."""
    r = np.asarray(ranges, np.float64)
    angles = angle_min + np.arange(len(r)) * angle_increment
    hit = np.isfinite(r) & (r >= range_min) & (r <= range_max)
    used = hit.copy()
    if source.inf_is_valid:
        free = np.isposinf(r)
        r = np.where(free, range_max - 1e-4, r)  # as Nav2: a tenth of a millimetre short
        used |= free
    r, angles, hit = r[used], angles[used], hit[used]
    x, y, yaw = sensor_pose
    return Observation(
        (x, y),
        x + r * np.cos(yaw + angles),
        y + r * np.sin(yaw + angles),
        r,
        hit,
        source,
    )


class ObstacleLayer:
    """The layer's own grid (rows y, columns x, as the costmap's) and its updates."""

    def __init__(
        self,
        shape: tuple[int, int],
        resolution: float,
        origin: tuple[float, float],
        *,
        track_unknown_space: bool = True,
    ) -> None:
        self.resolution = float(resolution)
        self.origin_x, self.origin_y = float(origin[0]), float(origin[1])
        self.default = NO_INFORMATION if track_unknown_space else FREE_SPACE
        self.grid = np.full(shape, self.default, np.uint8)

    def reset(self) -> None:
        """Forget everything seen (``clear_entirely_*``)."""
        self.grid[:] = self.default

    def _cells(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        h, w = self.grid.shape
        mx = np.floor((x - self.origin_x) / self.resolution).astype(np.int64)
        my = np.floor((y - self.origin_y) / self.resolution).astype(np.int64)
        inside = (mx >= 0) & (my >= 0) & (mx < w) & (my < h)
        return mx, my, inside

    def raytrace(self, obs: Observation) -> None:
        """Clear the cells each beam crossed (not its end point's), within the raytrace ranges."""
        src = obs.source
        if len(obs.ranges) == 0:
            return
        ox, oy = obs.origin
        reach = np.minimum(obs.ranges, src.raytrace_max_range)
        # Samples every half cell along each beam: every crossed cell gets at least one.
        step = self.resolution / 2.0
        count = int(math.ceil(float(reach.max()) / step)) + 1
        t = np.arange(count) * step
        length = np.maximum(obs.ranges, 1e-9)
        dx = (obs.ends_x - ox) / length
        dy = (obs.ends_y - oy) / length
        along = (t[None, :] >= src.raytrace_min_range) & (t[None, :] < reach[:, None])
        xs = ox + dx[:, None] * t[None, :]
        ys = oy + dy[:, None] * t[None, :]
        mx, my, inside = self._cells(xs, ys)
        end_mx, end_my, _ = self._cells(obs.ends_x, obs.ends_y)
        # The end point's cell is the obstacle itself: the beam stopped there.
        at_end = (mx == end_mx[:, None]) & (my == end_my[:, None]) & obs.hit[:, None]
        keep = along & inside & ~at_end
        self.grid[my[keep], mx[keep]] = FREE_SPACE

    def mark(self, obs: Observation) -> None:
        """Make the cell of every end point within the obstacle ranges lethal."""
        src = obs.source
        near = obs.hit & (obs.ranges < src.obstacle_max_range)
        near &= obs.ranges >= src.obstacle_min_range
        mx, my, inside = self._cells(obs.ends_x[near], obs.ends_y[near])
        self.grid[my[inside], mx[inside]] = LETHAL_OBSTACLE

    def update(self, observations: list[Observation]) -> None:
        """Clearing first, then marking (so a beam's neighbours never wipe what it saw)."""
        for obs in observations:
            if obs.source.clearing:
                self.raytrace(obs)
        for obs in observations:
            if obs.source.marking:
                self.mark(obs)

    def clear_footprint(self, x: float, y: float, radius: float) -> None:
        """Free the cells whose centres lie under a round robot at (x, y)."""
        h, w = self.grid.shape
        reach = int(math.ceil(radius / self.resolution)) + 1
        cx = int(math.floor((x - self.origin_x) / self.resolution))
        cy = int(math.floor((y - self.origin_y) / self.resolution))
        x0, x1 = max(cx - reach, 0), min(cx + reach + 1, w)
        y0, y1 = max(cy - reach, 0), min(cy + reach + 1, h)
        if x0 >= x1 or y0 >= y1:
            return
        jj, ii = np.mgrid[y0:y1, x0:x1]
        px = self.origin_x + (ii + 0.5) * self.resolution
        py = self.origin_y + (jj + 0.5) * self.resolution
        under = np.hypot(px - x, py - y) <= radius
        self.grid[jj[under], ii[under]] = FREE_SPACE

    def update_with_max(self, master: np.ndarray) -> np.ndarray:
        """The costmap with this layer on top (Nav2's ``updateWithMax``), a new array."""
        out = master.copy()
        known = self.grid != NO_INFORMATION
        take = known & ((master == NO_INFORMATION) | (master < self.grid))
        out[take] = self.grid[take]
        return out
