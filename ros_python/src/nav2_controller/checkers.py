"""The goal checker and the progress checker of Nav2's controller server.

- ``SimpleGoalChecker`` (``goal_checker``): the goal is reached when the robot
  is within ``xy_goal_tolerance`` (0.25 m) of the path's last pose and its
  heading within ``yaw_goal_tolerance`` (0.25 rad). ``stateful`` (true): once
  the position was reached it stays reached while the robot turns.
- ``SimpleProgressChecker`` (``progress_checker``): the robot must move
  ``required_movement_radius`` (0.5 m) away from where it last made progress
  within ``movement_time_allowance`` (10 s), else FAILED_TO_MAKE_PROGRESS.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass
class SimpleGoalChecker:
    xy_goal_tolerance: float = 0.25
    yaw_goal_tolerance: float = 0.25
    stateful: bool = True
    check_xy: bool = True

    def reset(self) -> None:
        self.check_xy = True

    def is_goal_reached(
        self, pose: tuple[float, float, float], goal: tuple[float, float, float]
    ) -> bool:
        if self.check_xy:
            if math.hypot(goal[0] - pose[0], goal[1] - pose[1]) > self.xy_goal_tolerance:
                return False
            if self.stateful:
                self.check_xy = False
        dyaw = math.atan2(math.sin(goal[2] - pose[2]), math.cos(goal[2] - pose[2]))
        return abs(dyaw) <= self.yaw_goal_tolerance


@dataclass
class SimpleProgressChecker:
    required_movement_radius: float = 0.5
    movement_time_allowance: float = 10.0
    baseline: tuple[float, float] | None = None
    baseline_time: float = 0.0

    def reset(self) -> None:
        self.baseline = None

    def check(self, pose: tuple[float, float, float], now: float) -> bool:
        """False when the robot has not moved far enough for too long."""
        if self.baseline is None or (
            math.hypot(pose[0] - self.baseline[0], pose[1] - self.baseline[1])
            > self.required_movement_radius
        ):
            self.baseline, self.baseline_time = (pose[0], pose[1]), now
            return True
        return now - self.baseline_time <= self.movement_time_allowance
