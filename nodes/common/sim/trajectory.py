"""Joint trajectories for a position-controlled arm, as a trajectory controller follows them.

A ``trajectory_msgs/JointTrajectory`` names joints and gives waypoints with a
``time_from_start``. We check it (names known, one position per joint, finite,
within limits, times increasing) and then sample it: linear interpolation from
where the joints were when it arrived to each waypoint in turn.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np


class TrajectoryError(ValueError):
    """A trajectory the controller refuses; the message says why."""


@dataclass(frozen=True)
class Plan:
    """A checked trajectory: joint indices, waypoint times (s) and positions."""

    joints: tuple[int, ...]  # indices into the controller's joint list
    times: np.ndarray  # (n,) seconds after the start, increasing
    positions: np.ndarray  # (n, len(joints))
    start: np.ndarray  # positions of those joints when the plan began

    def sample(self, elapsed: float) -> np.ndarray:
        """Positions of ``joints`` ``elapsed`` seconds after the start."""
        times = np.concatenate([[0.0], self.times])
        points = np.vstack([self.start, self.positions])
        return np.array([np.interp(elapsed, times, points[:, k]) for k in range(len(self.joints))])

    @property
    def duration(self) -> float:
        return float(self.times[-1])


def check_trajectory(
    names: Sequence[str],
    points: Sequence[tuple[Sequence[float], float]],
    known: Sequence[str],
    limits: Mapping[str, tuple[float, float]],
    current: Sequence[float],
) -> Plan:
    """Turn (joint names, [(positions, seconds)]) into a Plan, or say what is wrong."""
    unknown = [n for n in names if n not in known]
    if unknown:
        raise TrajectoryError(
            f"unknown joint name(s) {unknown}: this arm's joints are {list(known)}"
        )
    if len(set(names)) != len(names):
        raise TrajectoryError(f"joint names repeat: {list(names)}")
    if not names or not points:
        raise TrajectoryError("the trajectory has no joint names or no points")
    times: list[float] = []
    positions: list[list[float]] = []
    for i, (pos, t) in enumerate(points):
        if len(pos) != len(names):
            raise TrajectoryError(
                f"point {i} has {len(pos)} positions for {len(names)} joint names"
            )
        if not all(math.isfinite(p) for p in pos) or not math.isfinite(t):
            raise TrajectoryError(f"point {i} has a non-finite position or time")
        if times and t <= times[-1]:
            raise TrajectoryError(f"point {i}: time_from_start must increase ({t} s)")
        for name, p in zip(names, pos, strict=True):
            lo, hi = limits[name]
            if not lo - 1e-6 <= p <= hi + 1e-6:
                raise TrajectoryError(
                    f"point {i}: {name} = {p:.3f} rad is outside its limits [{lo:.3f}, {hi:.3f}]"
                )
        times.append(float(t))
        positions.append([float(p) for p in pos])
    index = tuple(known.index(n) for n in names)
    if times[0] <= 0.0:  # a first point "now": reach it in one control period
        times = [max(t, 0.01) for t in times]
    return Plan(
        joints=index,
        times=np.array(times),
        positions=np.array(positions),
        start=np.array([current[k] for k in index], dtype=float),
    )
