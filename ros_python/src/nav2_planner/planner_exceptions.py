"""Why a plan failed, as ``nav2_core/planner_exceptions.hpp`` names the reasons.

The planner server turns each into the error code of
nav2_msgs/action/ComputePathToPose (``ERROR_CODE``).
"""

from __future__ import annotations

from nav2_msgs.action import ComputePathToPose


class PlannerException(RuntimeError):
    """Any planning failure; the server answers UNKNOWN for a plain one."""

    error_code = ComputePathToPose.Result.UNKNOWN


class InvalidPlanner(PlannerException):
    error_code = ComputePathToPose.Result.INVALID_PLANNER


class PlannerTFError(PlannerException):
    error_code = ComputePathToPose.Result.TF_ERROR


class StartOutsideMapBounds(PlannerException):
    error_code = ComputePathToPose.Result.START_OUTSIDE_MAP


class GoalOutsideMapBounds(PlannerException):
    error_code = ComputePathToPose.Result.GOAL_OUTSIDE_MAP


class StartOccupied(PlannerException):
    error_code = ComputePathToPose.Result.START_OCCUPIED


class GoalOccupied(PlannerException):
    error_code = ComputePathToPose.Result.GOAL_OCCUPIED


class PlannerTimedOut(PlannerException):
    error_code = ComputePathToPose.Result.TIMEOUT


class NoValidPathCouldBeFound(PlannerException):
    error_code = ComputePathToPose.Result.NO_VALID_PATH


class PlannerCancelled(PlannerException):
    """The goal was cancelled while planning (no error code: the goal ends canceled)."""
