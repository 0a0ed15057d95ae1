"""The likelihood field laser model (``laser_model_type: likelihood_field``).

Each beam's end point is looked up in the map's distance field: a beam that
ends d metres from the nearest obstacle scores ``pz = z_hit * exp(-d^2 / (2
sigma_hit^2)) + z_rand / range_max`` (an end point off the map counts as
``laser_likelihood_max_dist`` away). Beams at or beyond ``range_max`` (saw
nothing) and NaN readings carry no information and are left out. A particle's
weight is multiplied by ``1 + sum(pz^3)`` over the beams it uses: Nav2's
amcl sums cubes instead of multiplying the beams' probabilities (which would
make the filter overconfident, the beams not being independent), and so do
we. At most ``max_beams`` beams are used, evenly spaced over the scan.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from nav2_amcl.map import AmclMap


@dataclass
class ScanBeams:
    """One scan as the model needs it: ranges and their bearings in the robot's frame."""

    ranges: np.ndarray  # (B,) m
    bearings: np.ndarray  # (B,) rad, in the base frame
    range_max: float
    laser_pose: tuple[float, float, float] = (0.0, 0.0, 0.0)  # the scanner in the base frame

    @classmethod
    def from_scan(
        cls,
        ranges: np.ndarray,
        angle_min: float,
        angle_increment: float,
        range_min: float,
        range_max: float,
        max_beams: int,
        laser_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> ScanBeams:
        """Pick ``max_beams`` evenly spaced beams; readings under range_min count as range_max."""
        r = np.asarray(ranges, np.float64)
        count = len(r)
        step = max(1, (count - 1) // max(1, max_beams - 1)) if max_beams > 1 else max(count, 1)
        index = np.arange(0, count, step)[: max(max_beams, 1)]
        picked = r[index].copy()
        picked[picked <= range_min] = range_max  # as Nav2: a too-close reading says nothing
        bearings = angle_min + index * angle_increment + laser_pose[2]
        return cls(picked, bearings, float(range_max), laser_pose)


class LikelihoodFieldModel:
    def __init__(
        self, z_hit: float, z_rand: float, sigma_hit: float, max_occ_dist: float, amcl_map: AmclMap
    ) -> None:
        self.z_hit, self.z_rand, self.sigma_hit = z_hit, z_rand, sigma_hit
        self.map = amcl_map
        if amcl_map.distances is None or amcl_map.max_occ_dist != max_occ_dist:
            amcl_map.update_cspace(max_occ_dist)
        self._field: np.ndarray | None = None  # pz per cell, for one range_max
        self._field_range = math.nan

    def _pz_field(self, range_max: float) -> tuple[np.ndarray, float]:
        """pz of an end point in each cell (flattened), and off the map."""
        z_rand_mult = self.z_rand / range_max if range_max > 0 else 0.0
        denominator = 2.0 * self.sigma_hit * self.sigma_hit
        if self._field is None or self._field_range != range_max:
            d = self.map.distances
            assert d is not None
            field = self.z_hit * np.exp(-(d.astype(np.float64) ** 2) / denominator) + z_rand_mult
            self._field = field.reshape(-1)
            self._field_range = range_max
        z = self.map.max_occ_dist
        off_map = self.z_hit * math.exp(-(z * z) / denominator) + z_rand_mult
        return self._field, off_map

    def weights(self, poses: np.ndarray, scan: ScanBeams) -> np.ndarray:
        """Each particle's factor ``1 + sum(pz^3)`` (N,) for this scan."""
        keep = np.isfinite(scan.ranges) & (scan.ranges < scan.range_max)
        r, bearing = scan.ranges[keep], scan.bearings[keep]
        n = len(poses)
        if len(r) == 0:
            return np.ones(n)
        field, off_map = self._pz_field(scan.range_max)
        lx, ly, _lyaw = scan.laser_pose
        c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
        sensor_x = poses[:, 0] + c * lx - s * ly
        sensor_y = poses[:, 1] + s * lx + c * ly
        # End points: cos(yaw + b) = cos yaw cos b - sin yaw sin b (outer products, no N x B trig).
        rc, rs = r * np.cos(bearing), r * np.sin(bearing)
        ex = sensor_x[:, None] + np.outer(c, rc) - np.outer(s, rs)
        ey = sensor_y[:, None] + np.outer(s, rc) + np.outer(c, rs)
        amap = self.map
        i = np.floor((ex - amap.origin_x) * (1.0 / amap.resolution)).astype(np.int64)
        j = np.floor((ey - amap.origin_y) * (1.0 / amap.resolution)).astype(np.int64)
        inside = (i >= 0) & (i < amap.width) & (j >= 0) & (j < amap.height)
        flat = np.where(inside, j * amap.width + i, 0)
        pz = np.where(inside, field[flat], off_map)
        return 1.0 + (pz * pz * pz).sum(axis=1)
