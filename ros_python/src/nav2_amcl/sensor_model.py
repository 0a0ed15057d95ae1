"""The likelihood field laser models (``laser_model_type``: ``likelihood_field``, ``_prob``).

Each beam's end point is looked up in the map's distance field: a beam that
ends d metres from the nearest obstacle scores ``pz = z_hit * exp(-d^2 / (2
sigma_hit^2)) + z_rand / range_max`` (an end point off the map counts as
``laser_likelihood_max_dist`` away). Beams at or beyond ``range_max`` (saw
nothing) and NaN readings carry no information and are left out. A particle's
weight is multiplied by ``1 + sum(pz^3)`` over the beams it uses: Nav2's
amcl sums cubes instead of multiplying the beams' probabilities (which would
make the filter overconfident, the beams not being independent), and so do
we. At most ``max_beams`` beams are used, evenly spaced over the scan.

``likelihood_field_prob`` scores each end point the same way but multiplies
the beams' ``pz`` (a sum of logs), as the textbook does: far sharper, so a
filter fed by it tracks within a few centimetres and a degree on this robot,
where the sum of cubes lets the estimate wander a decimetre and several
degrees. Its ``do_beamskip`` leaves out the beams that most particles cannot
explain (a box or a person not on the map), once the filter has converged:
a beam counts for a particle when its end point lies within
``beam_skip_distance`` of a mapped obstacle, and is used when more than
``beam_skip_threshold`` of the particles agree; when even
``beam_skip_error_threshold`` of the beams would be left out, the filter has
probably converged to a wrong pose and all beams are used.
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
        found = self.end_points(poses, scan)
        if found is None:
            return np.ones(len(poses))
        flat, inside, _keep = found
        field, off_map = self._pz_field(scan.range_max)
        pz = np.where(inside, field[flat], off_map)
        return 1.0 + (pz * pz * pz).sum(axis=1)

    def end_points(
        self, poses: np.ndarray, scan: ScanBeams
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """Each used beam's end point per particle: its flat cell index and whether it is on
        the map (N x B each), and which beams were used; None when no beam saw anything.

        Beams at or beyond range_max (saw nothing) and NaN readings are left out."""
        keep = np.isfinite(scan.ranges) & (scan.ranges < scan.range_max)
        r, bearing = scan.ranges[keep], scan.bearings[keep]
        if len(r) == 0:
            return None
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
        return np.where(inside, j * amap.width + i, 0), inside, keep


class LikelihoodFieldProbModel(LikelihoodFieldModel):
    """``likelihood_field_prob``: the product of the beams' ``pz``, with beam skipping."""

    def __init__(
        self,
        z_hit: float,
        z_rand: float,
        sigma_hit: float,
        max_occ_dist: float,
        amcl_map: AmclMap,
        do_beamskip: bool = False,
        beam_skip_distance: float = 0.5,
        beam_skip_threshold: float = 0.3,
        beam_skip_error_threshold: float = 0.9,
    ) -> None:
        super().__init__(z_hit, z_rand, sigma_hit, max_occ_dist, amcl_map)
        self.do_beamskip = do_beamskip
        self.beam_skip_distance = beam_skip_distance
        self.beam_skip_threshold = beam_skip_threshold
        self.beam_skip_error_threshold = beam_skip_error_threshold
        self.skipped = 0  # beams left out by the last update (for the log)
        self.all_beams_forced = False  # the last update found too few beams on the map
        # Each particle's mean log pz over every beam of the last scan, the skipped ones too:
        # how well the scan fits there, comparable from scan to scan (recovery's averages).
        self.fit_log: np.ndarray | None = None
        self._log_field: np.ndarray | None = None  # log pz per cell (_field keeps pz)
        self._log_field_range = math.nan

    def _log_pz_field(self, range_max: float) -> tuple[np.ndarray, float]:
        # Here z_rand spreads over the whole range (Nav2's 1 / range_max, times z_rand).
        z_rand_mult = 1.0 / range_max if range_max > 0 else 0.0
        denominator = 2.0 * self.sigma_hit * self.sigma_hit
        if self._log_field is None or self._log_field_range != range_max:
            d = self.map.distances
            assert d is not None
            pz = self.z_hit * np.exp(-(d.astype(np.float64) ** 2) / denominator)
            self._log_field = np.log(pz + self.z_rand * z_rand_mult).reshape(-1)
            self._log_field_range = range_max
        z = self.map.max_occ_dist
        off_map = self.z_hit * math.exp(-(z * z) / denominator) + self.z_rand * z_rand_mult
        return self._log_field, math.log(off_map)

    def log_weights(self, poses: np.ndarray, scan: ScanBeams, converged: bool) -> np.ndarray:
        """Each particle's ``sum(log pz)`` over the beams used (N,)."""
        self.skipped, self.all_beams_forced, self.fit_log = 0, False, None
        found = self.end_points(poses, scan)
        if found is None:
            return np.zeros(len(poses))
        flat, inside, _keep = found
        log_field, log_off_map = self._log_pz_field(scan.range_max)
        log_pz = np.where(inside, log_field[flat], log_off_map)
        self.fit_log = log_pz.mean(axis=1)
        if self.do_beamskip and converged:
            distances = self.map.distances
            assert distances is not None
            near = inside & (distances.reshape(-1)[flat] < self.beam_skip_distance)
            agree = near.mean(axis=0) > self.beam_skip_threshold
            skipped = int((~agree).sum())
            if skipped >= agree.size * self.beam_skip_error_threshold:
                self.all_beams_forced = True  # probably converged to a wrong pose
            else:
                self.skipped = skipped
                log_pz = log_pz[:, agree]
        return log_pz.sum(axis=1)

    def weights(self, poses: np.ndarray, scan: ScanBeams, converged: bool = False) -> np.ndarray:
        """Each particle's factor ``prod(pz)`` (N,) for this scan (may underflow to 0)."""
        return np.exp(self.log_weights(poses, scan, converged))
