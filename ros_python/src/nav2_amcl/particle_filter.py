"""The particle filter: Monte Carlo localization with KLD-sampling and augmented MCL recovery.

- ``init_gaussian``: ``max_particles`` poses drawn around an initial pose with
  its covariance (an ``/initialpose``); ``init_uniform``: spread over the
  map's free cells, any heading (``reinitialize_global_localization``).
- ``update_action``: the motion model moves every particle.
- ``update_sensor``: the sensor model multiplies every weight (with
  ``likelihood_field_prob``, ours: only once the particles have gathered,
  ``update_gathered``; a spread is weighed with the sum of cubes); the average
  weight feeds two running averages, ``w_slow`` and ``w_fast``
  (``recovery_alpha_slow`` / ``recovery_alpha_fast``). When the short-term
  average falls below the long-term one the scans fit worse than they used
  to (the robot was kidnapped): resampling then puts a fraction ``1 -
  w_fast / w_slow`` of the new particles at random free poses. With
  ``likelihood_field_prob`` (ours) the fit is the particles' mean per-beam
  likelihood over all beams, the averages go on through the spread and
  through injections (Nav2 starts them again), and only a drop of
  ``RECOVERY_MIN_DROP`` or more injects: replayed office tours with 0.01 / 0.2,
  the robot carried 3 m, found it again in 13 of 15 cases within 60 s (without
  recovery 3 of 15), and tracked as closely as without recovery.
- ``resample``: low-variance (systematic) resampling, the draws taken in a
  random order, stopping once there are enough particles for the number of
  distinct (0.5 m, 0.5 m, 10 degree) bins they fill (KLD-sampling, Fox 2003:
  ``pf_err`` is the bound on the error, ``pf_z`` the quantile as Nav2 uses
  it), never fewer than ``min_particles`` nor more than ``max_particles``.
- ``estimate``: the particles are grouped into clusters of touching bins;
  the heaviest cluster's weighted mean is the pose, the whole set's spread
  its covariance (as Nav2 publishes on ``/amcl_pose``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from nav2_amcl.map import AmclMap
from nav2_amcl.motion_model import DifferentialMotionModel, OmniMotionModel, normalize
from nav2_amcl.sensor_model import LikelihoodFieldModel, LikelihoodFieldProbModel, ScanBeams

BIN_SIZE = (0.5, 0.5, math.radians(10.0))  # the kd-tree's cells (m, m, rad)
DIFFERENTIAL = ("nav2_amcl::DifferentialMotionModel", "differential")
OMNI = ("nav2_amcl::OmniMotionModel", "omnidirectional", "omni")
LASER_MODELS = ("likelihood_field", "likelihood_field_prob")
CONVERGED_SPREAD = 0.5  # m: every particle this close to the mean in x and y (Nav2's pf)
GATHERED_SPREAD = 0.5  # m: the particles' spread (x and y std combined) of a filter that tracks
# Ours, likelihood_field_prob: random particles only once the short-term fit fell this far (a
# share) below the long-term one. Smaller drops are the scans' own noise: injecting on them
# scattered a tracking filter (replayed office tours: mean error 0.4 m instead of 0.012 m).
RECOVERY_MIN_DROP = 0.15


@dataclass
class FilterParameters:
    """The filter's share of amcl's parameters, with Nav2 Jazzy's names and defaults."""

    alpha1: float = 0.2
    alpha2: float = 0.2
    alpha3: float = 0.2
    alpha4: float = 0.2
    alpha5: float = 0.2
    laser_likelihood_max_dist: float = 2.0
    laser_max_range: float = 100.0
    laser_min_range: float = -1.0
    max_beams: int = 60
    min_particles: int = 500
    max_particles: int = 2000
    pf_err: float = 0.05
    pf_z: float = 0.99
    recovery_alpha_fast: float = 0.0
    recovery_alpha_slow: float = 0.0
    resample_interval: int = 1
    robot_model_type: str = "nav2_amcl::DifferentialMotionModel"
    sigma_hit: float = 0.2
    z_hit: float = 0.5
    z_rand: float = 0.5
    z_max: float = 0.05
    z_short: float = 0.05
    laser_model_type: str = "likelihood_field"
    do_beamskip: bool = False
    beam_skip_distance: float = 0.5
    beam_skip_threshold: float = 0.3
    beam_skip_error_threshold: float = 0.9

    def check(self) -> str:
        """Why these values cannot work ('' when they can)."""
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, float) and not math.isfinite(value):
                return f"{f.name} must be a finite number, not {value}"
        for name in ("alpha1", "alpha2", "alpha3", "alpha4", "alpha5"):
            if getattr(self, name) < 0.0:
                value = getattr(self, name)
                return f"{name} is a noise variance factor and cannot be negative ({value})"
        if self.min_particles < 1:
            return f"min_particles must be at least 1, not {self.min_particles}"
        if self.max_particles < self.min_particles:
            return (
                f"max_particles ({self.max_particles}) must not be smaller than min_particles "
                f"({self.min_particles})"
            )
        if self.max_beams < 2:
            return f"max_beams must be at least 2, not {self.max_beams}"
        if self.resample_interval < 1:
            return f"resample_interval must be at least 1, not {self.resample_interval}"
        if not 0.0 < self.pf_err < 1.0:
            return f"pf_err must be between 0 and 1 (exclusive), not {self.pf_err}"
        if not 0.0 < self.pf_z < 1.0:
            return f"pf_z must be between 0 and 1 (exclusive), not {self.pf_z}"
        if self.sigma_hit <= 0.0:
            return f"sigma_hit must be a positive number of metres, not {self.sigma_hit}"
        if self.laser_likelihood_max_dist <= 0.0:
            return (
                "laser_likelihood_max_dist must be a positive number of metres, not "
                f"{self.laser_likelihood_max_dist}"
            )
        if self.z_hit < 0.0 or self.z_rand < 0.0 or self.z_hit + self.z_rand <= 0.0:
            return f"z_hit and z_rand must be >= 0 and not both 0 ({self.z_hit}, {self.z_rand})"
        for name in ("recovery_alpha_slow", "recovery_alpha_fast"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                return f"{name} must be between 0.0 and 1.0, not {getattr(self, name)}"
        if self.recovery_alpha_slow > 0.0 and self.recovery_alpha_fast <= self.recovery_alpha_slow:
            return (
                f"recovery_alpha_fast ({self.recovery_alpha_fast}) must be larger than "
                f"recovery_alpha_slow ({self.recovery_alpha_slow}) for recovery to work"
            )
        if self.laser_model_type not in LASER_MODELS:
            return (
                f"laser_model_type '{self.laser_model_type}' is not implemented here: use "
                f"'{LASER_MODELS[0]}' or '{LASER_MODELS[1]}'"
            )
        if self.robot_model_type not in DIFFERENTIAL + OMNI:
            return (
                f"robot_model_type '{self.robot_model_type}' is not known: use "
                f"'{DIFFERENTIAL[0]}' or '{OMNI[0]}'"
            )
        return ""


@dataclass(frozen=True)
class PoseEstimate:
    """The heaviest cluster's mean pose and the set's covariance (x, y, yaw)."""

    x: float
    y: float
    yaw: float
    covariance: np.ndarray  # (3, 3)
    weight: float  # the cluster's share of the total weight
    clusters: int


def kld_limit(k: int | np.ndarray, pf_err: float, pf_z: float, lo: int, hi: int) -> np.ndarray:
    """How many particles ``k`` occupied bins need (Fox's KLD bound), within [lo, hi]."""
    k = np.asarray(k, np.float64)
    km1 = np.maximum(k - 1.0, 1.0)
    b = 2.0 / (9.0 * km1)
    x = 1.0 - b + np.sqrt(b) * pf_z
    n = np.ceil(km1 / (2.0 * pf_err) * x**3)
    n = np.where(k <= 1.0, hi, n)
    return np.clip(n, lo, hi).astype(np.int64)


def bin_keys(poses: np.ndarray) -> np.ndarray:
    """The (ix, iy, iyaw) bin of each pose, (N, 3) int64."""
    keys = np.empty((len(poses), 3), np.int64)
    for axis, size in enumerate(BIN_SIZE):
        keys[:, axis] = np.floor(poses[:, axis] / size)
    return keys


def cluster_labels(keys: np.ndarray) -> np.ndarray:
    """Which cluster of touching bins (26-neighbours, heading wrapping round) each pose is in."""
    yaw_bins = int(round(2 * math.pi / BIN_SIZE[2]))
    keys = keys.copy()
    keys[:, 2] %= yaw_bins
    lo = keys.min(axis=0) - 1
    span = keys.max(axis=0) - lo + 2
    span[2] = yaw_bins

    def encode(k: np.ndarray) -> np.ndarray:
        return ((k[:, 0] - lo[0]) * span[1] + (k[:, 1] - lo[1])) * span[2] + k[:, 2]

    bins, per_pose = np.unique(encode(keys), return_inverse=True)
    per_pose = per_pose.reshape(-1)
    count = len(bins)
    # Each occupied bin's key back, then its occupied neighbours: the edges of a graph.
    bx, rest = np.divmod(bins, span[1] * span[2])
    by, byaw = np.divmod(rest, span[2])
    src_list, dst_list = [], []
    for a in (-1, 0, 1):
        for b in (-1, 0, 1):
            for c in (-1, 0, 1):
                if (a, b, c) == (0, 0, 0):
                    continue
                code = ((bx + a) * span[1] + (by + b)) * span[2] + (byaw + c) % yaw_bins
                at = np.minimum(np.searchsorted(bins, code), count - 1)
                hit = bins[at] == code
                src_list.append(np.flatnonzero(hit))
                dst_list.append(at[hit])
    src, dst = np.concatenate(src_list), np.concatenate(dst_list)
    labels = np.arange(count)
    while True:  # the smallest bin index of each connected group, by pointer jumping
        new = labels.copy()
        np.minimum.at(new, src, labels[dst])
        new = new[new]
        if np.array_equal(new, labels):
            break
        labels = new
    return np.unique(labels, return_inverse=True)[1].reshape(-1)[per_pose]


class ParticleFilter:
    def __init__(
        self, params: FilterParameters, amcl_map: AmclMap, seed: int | None = None
    ) -> None:
        problem = params.check()
        if problem:
            raise ValueError(problem)
        self.params = params
        self.map = amcl_map
        self.rng = np.random.default_rng(seed)
        if params.robot_model_type in OMNI:
            self.motion: DifferentialMotionModel | OmniMotionModel = OmniMotionModel(
                params.alpha1, params.alpha2, params.alpha3, params.alpha4, params.alpha5
            )
        else:
            self.motion = DifferentialMotionModel(
                params.alpha1, params.alpha2, params.alpha3, params.alpha4
            )
        self.sensor: LikelihoodFieldModel
        if params.laser_model_type == "likelihood_field_prob":
            self.sensor = LikelihoodFieldProbModel(
                params.z_hit,
                params.z_rand,
                params.sigma_hit,
                params.laser_likelihood_max_dist,
                amcl_map,
                params.do_beamskip,
                params.beam_skip_distance,
                params.beam_skip_threshold,
                params.beam_skip_error_threshold,
            )
        else:
            self.sensor = LikelihoodFieldModel(
                params.z_hit,
                params.z_rand,
                params.sigma_hit,
                params.laser_likelihood_max_dist,
                amcl_map,
            )
        self.free = amcl_map.free_cells()
        if len(self.free) == 0:
            raise ValueError("the map has no free cell: there is nowhere to localize")
        self.poses = np.zeros((params.max_particles, 3))
        self.weights = np.full(params.max_particles, 1.0 / params.max_particles)
        self.w_slow = self.w_fast = 0.0
        self.resample_count = 0
        self.converged = False
        self.gathered = False

    @property
    def count(self) -> int:
        return len(self.poses)

    # --- initialisation ---
    def init_gaussian(self, mean: tuple[float, float, float], cov: np.ndarray) -> None:
        """``max_particles`` poses around ``mean`` with covariance ``cov`` (3 x 3)."""
        n = self.params.max_particles
        cov = np.asarray(cov, np.float64).reshape(3, 3)
        cov = (cov + cov.T) / 2.0
        values, vectors = np.linalg.eigh(cov)
        spread = vectors * np.sqrt(np.maximum(values, 0.0))
        draws = self.rng.standard_normal((n, 3)) @ spread.T
        self.poses = np.asarray(mean, np.float64)[None, :] + draws
        self.poses[:, 2] = normalize(self.poses[:, 2])
        self.weights = np.full(n, 1.0 / n)
        self.w_slow = self.w_fast = 0.0
        self.converged = False
        self.update_gathered()

    def take_particles(self, other: ParticleFilter) -> None:
        """Carry on from ``other``'s particles and averages (a new map, the same robot)."""
        self.poses, self.weights = other.poses.copy(), other.weights.copy()
        self.w_slow, self.w_fast = other.w_slow, other.w_fast
        self.resample_count = other.resample_count
        self.converged, self.gathered = other.converged, other.gathered
        self.rng = other.rng

    def random_poses(self, n: int) -> np.ndarray:
        """Poses at the centres of random free cells, any heading."""
        x, y = self.map.cell_centres(self.rng.choice(self.free, n))
        yaw = self.rng.uniform(-math.pi, math.pi, n)
        return np.stack([x, y, yaw], axis=1)

    def init_uniform(self) -> None:
        n = self.params.max_particles
        self.poses = self.random_poses(n)
        self.weights = np.full(n, 1.0 / n)
        self.w_slow = self.w_fast = 0.0
        self.converged = False
        self.update_gathered()

    # --- the updates ---
    def update_action(
        self, pose: tuple[float, float, float], delta: tuple[float, float, float]
    ) -> None:
        self.motion.odometry_update(self.poses, pose, delta, self.rng)

    def update_sensor(self, scan: ScanBeams) -> float:
        """Weigh the particles by the scan; the total weight before normalising."""
        if isinstance(self.sensor, LikelihoodFieldProbModel) and self.gathered:
            # A product of many beams' pz is tiny: weigh in logs, so that the relative
            # weights survive where the absolute ones would underflow to 0.
            prior = self.weights
            with np.errstate(divide="ignore"):
                log_w = np.log(prior)
            log_w = log_w + self.sensor.log_weights(self.poses, scan, self.converged)
            top = float(log_w.max())
            if not math.isfinite(top):
                self.weights = np.full(self.count, 1.0 / self.count)
                return 0.0
            scaled = np.exp(log_w - top)
            kept = float(scaled.sum())
            self.weights = scaled / kept
            total = math.exp(top) * kept  # 0.0 when it underflows
            fit = self.sensor.fit_log
            if fit is not None:
                self.update_recovery_averages(float(np.dot(prior, np.exp(fit))))
            return total
        else:
            # LikelihoodFieldModel's own weights: the sum of cubes, whichever model was chosen
            prior = self.weights
            cubes = LikelihoodFieldModel.weights(self.sensor, self.poses, scan)
            self.weights = self.weights * cubes
            total = float(self.weights.sum())
            if not (total > 0.0 and math.isfinite(total)):
                self.weights = np.full(self.count, 1.0 / self.count)
                return total
            self.weights /= total
            if isinstance(self.sensor, LikelihoodFieldProbModel):
                # The recovery's fit as a gathered filter measures it (comparable across both).
                if self.params.recovery_alpha_slow > 0.0:
                    self.sensor.log_weights(self.poses, scan, False)
                    fit = self.sensor.fit_log
                    if fit is not None:
                        self.update_recovery_averages(float(np.dot(prior, np.exp(fit))))
                return total
        if total > 0.0 and math.isfinite(total):
            # The average likelihood of the scan (the weights summed to 1 before). Nav2 divides
            # this by the particle count too, which makes KLD's changing count look like a
            # change of fit; the textbook's average does not.
            self.update_recovery_averages(total)
        return total

    def update_recovery_averages(self, w_avg: float) -> None:
        """``w_slow`` and ``w_fast``, the long- and short-term averages of how well scans fit.

        Ours, for the product of the beams (a gathered filter): the fit is each particle's
        geometric mean pz over all the scan's beams, averaged with the particles' weights,
        not the product itself. The product grows when beam skipping leaves out the beams
        that do not fit, which is just what a kidnapped filter's scans do, and it changes
        by orders of magnitude with the number of beams: as the recovery's measure it never
        fell after a kidnap (replayed office tours).
        """
        if not (w_avg > 0.0 and math.isfinite(w_avg)):
            return
        p = self.params
        if self.w_slow == 0.0:
            self.w_slow = w_avg
        else:
            self.w_slow += p.recovery_alpha_slow * (w_avg - self.w_slow)
        if self.w_fast == 0.0:
            self.w_fast = w_avg
        else:
            self.w_fast += p.recovery_alpha_fast * (w_avg - self.w_fast)

    def update(self, scan: ScanBeams) -> bool:
        """The sensor update, then resampling every ``resample_interval`` updates; resampled?"""
        self.update_sensor(scan)
        self.resample_count += 1
        if self.resample_count % self.params.resample_interval == 0:
            self.resample()
            return True
        return False

    def resample(self) -> None:
        p = self.params
        w_diff = 0.0
        prob = isinstance(self.sensor, LikelihoodFieldProbModel)
        if self.w_slow > 0.0:
            w_diff = max(0.0, 1.0 - self.w_fast / self.w_slow)
            if prob and w_diff < RECOVERY_MIN_DROP:
                w_diff = 0.0
        m = p.max_particles
        cumulative = np.cumsum(self.weights)
        cumulative /= cumulative[-1]
        positions = (self.rng.random() + np.arange(m)) / m
        picked = np.minimum(np.searchsorted(cumulative, positions, side="right"), self.count - 1)
        candidates = self.poses[self.rng.permutation(picked)]
        if w_diff > 0.0:
            inject = self.rng.random(m) < w_diff
            if inject.any():
                candidates[inject] = self.random_poses(int(inject.sum()))
        # KLD: the first n draws fill k(n) bins; stop at the first n above the bound for k(n).
        _, first = np.unique(bin_keys(candidates), axis=0, return_index=True)
        is_first = np.zeros(m, bool)
        is_first[first] = True
        k = np.cumsum(is_first)
        n = np.arange(1, m + 1)
        over = np.flatnonzero(n > kld_limit(k, p.pf_err, p.pf_z, p.min_particles, m))
        count = int(n[over[0]]) if len(over) else m
        self.poses = candidates[:count].copy()
        self.weights = np.full(count, 1.0 / count)
        if w_diff > 0.0 and not prob:  # Nav2's: both averages start again
            self.w_slow = self.w_fast = 0.0
        self.update_converged()
        self.update_gathered()

    def update_gathered(self) -> bool:
        """The particles gather round one pose: likelihood_field_prob may weigh them.

        Ours (Nav2 weighs with the product whenever it is chosen): from a spread (a global
        reinitialisation, a rough initial pose) the product of 60 beams keeps one or two of
        thousands of hypotheses after a single scan, often the wrong ones; the sum of cubes
        (likelihood_field) lets the scans rule them out over a few metres. So a spread
        filter weighs with the sum of cubes, a gathered one with the product.
        """
        spread = math.hypot(float(self.poses[:, 0].std()), float(self.poses[:, 1].std()))
        gathered = spread < GATHERED_SPREAD
        if gathered != self.gathered and not isinstance(self.sensor, LikelihoodFieldProbModel):
            self.w_slow = self.w_fast = 0.0  # the two models' likelihoods are not comparable
        self.gathered = gathered
        return gathered

    def update_converged(self) -> bool:
        """Every particle within CONVERGED_SPREAD of the mean in x and y (beam skipping's cue)."""
        mean = self.poses[:, :2].mean(axis=0)
        self.converged = bool(np.all(np.abs(self.poses[:, :2] - mean) <= CONVERGED_SPREAD))
        return self.converged

    # --- the answer ---
    def estimate(self) -> PoseEstimate:
        w = self.weights / self.weights.sum()
        labels = cluster_labels(bin_keys(self.poses))
        clusters = int(labels.max()) + 1
        cluster_w = np.bincount(labels, w, clusters)
        best = int(np.argmax(cluster_w))
        inside = labels == best
        wb = w[inside] / cluster_w[best]
        pose = self.poses[inside]
        x = float(np.dot(wb, pose[:, 0]))
        y = float(np.dot(wb, pose[:, 1]))
        yaw = math.atan2(
            float(np.dot(wb, np.sin(pose[:, 2]))), float(np.dot(wb, np.cos(pose[:, 2])))
        )
        # The whole set's covariance, as Nav2 publishes it.
        mx, my = float(np.dot(w, self.poses[:, 0])), float(np.dot(w, self.poses[:, 1]))
        dx, dy = self.poses[:, 0] - mx, self.poses[:, 1] - my
        cov = np.zeros((3, 3))
        cov[0, 0] = float(np.dot(w, dx * dx))
        cov[0, 1] = cov[1, 0] = float(np.dot(w, dx * dy))
        cov[1, 1] = float(np.dot(w, dy * dy))
        length = math.hypot(
            float(np.dot(w, np.cos(self.poses[:, 2]))), float(np.dot(w, np.sin(self.poses[:, 2])))
        )
        cov[2, 2] = -2.0 * math.log(max(length, 1e-12))
        return PoseEstimate(x, y, yaw, cov, float(cluster_w[best]), clusters)
