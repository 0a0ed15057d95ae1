"""A 2D laser scanner from MuJoCo ray casts (``mj_multiRay``), with range noise.

The rays leave a site on the robot, level with its base, one per degree
counter-clockwise from straight ahead (angle_min = -pi, as LaserScan expects
angles measured from the x axis of the scanner frame). A ray that hits
nothing within ``range_max`` reports ``inf``, as REP 117 asks.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np


def scan_angles(count: int) -> np.ndarray:
    """Ray angles (rad) from -pi, ``count`` of them, evenly spaced over a full turn."""
    return -math.pi + np.arange(count) * (2.0 * math.pi / count)


class Lidar:
    """Casts ``count`` horizontal rays from ``site`` into geoms of groups 0-2."""

    def __init__(
        self,
        model: mujoco.MjModel,
        site: str,
        count: int = 360,
        range_min: float = 0.12,
        range_max: float = 8.0,
        noise_std: float = 0.01,
        seed: int | None = None,
    ) -> None:
        self.model = model
        self.site_id = model.site(site).id
        self.body_id = int(model.site_bodyid[self.site_id])
        self.count = count
        self.angles = scan_angles(count)
        self.range_min = range_min
        self.range_max = range_max
        self.noise_std = noise_std
        self.local_dirs = np.stack(
            [np.cos(self.angles), np.sin(self.angles), np.zeros(count)], axis=1
        )
        # Groups 0-2 are the world and the arm; the mobile robot's own geoms are group 3.
        self.geomgroup = np.array([1, 1, 1, 0, 0, 0], dtype=np.uint8)
        self._geomid = np.zeros(count, dtype=np.int32)
        self._dist = np.zeros(count, dtype=np.float64)
        self.rng = np.random.default_rng(seed)

    def true_ranges(self, data: mujoco.MjData) -> np.ndarray:
        """Exact distances (m) along each ray; inf where nothing is within range_max."""
        origin = data.site_xpos[self.site_id].copy()
        rotation = data.site_xmat[self.site_id].reshape(3, 3)
        dirs = (self.local_dirs @ rotation.T).ravel()
        mujoco.mj_multiRay(
            self.model, data, origin, dirs, self.geomgroup, 1, self.body_id,
            self._geomid, self._dist, None, self.count, self.range_max,
        )  # fmt: skip
        ranges = self._dist.copy()
        ranges[(self._geomid < 0) | (ranges < 0) | (ranges > self.range_max)] = math.inf
        return ranges

    def measure(self, data: mujoco.MjData) -> np.ndarray:
        """What the scanner reports: true ranges plus Gaussian noise, clipped to its limits."""
        ranges = self.true_ranges(data)
        hit = np.isfinite(ranges)
        ranges[hit] += self.rng.normal(0.0, self.noise_std, int(hit.sum()))
        ranges[hit & (ranges < self.range_min)] = -math.inf  # too close: REP 117's -inf
        ranges[hit & (ranges > self.range_max)] = math.inf
        return ranges
