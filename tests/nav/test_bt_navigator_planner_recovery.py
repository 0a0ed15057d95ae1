"""bt_navigator tries a failing plan again as Nav2's tree does: after clearing the global costmap.

Nav2's tree wraps ComputePathToPose in a RecoveryNode: when planning fails with a
code a planner recovery may help with, it clears the global costmap and plans
once more. A lesson walk (ci98, one core busy) lost its goal without that: amcl's
heading was 10 degrees off while the robot turned, the scans drew streaks across
the doors into the global costmap, and three replans in a row found no path.

The real bt_navigator runs as its own process against this test's stand-ins
(tests/nav/test_bt_navigator_race.py), whose planner fails as each case says.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import pytest
from nav2_msgs.action import ComputePathToPose, FollowPath

from tests.nav.test_bt_navigator_race import StandIns, _path, navigate

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

SUCCEEDED, ABORTED = 4, 6  # action_msgs/GoalStatus
NO_VALID_PATH = ComputePathToPose.Result.NO_VALID_PATH
GOAL_OCCUPIED = ComputePathToPose.Result.GOAL_OCCUPIED
CLEAR_GLOBAL = "clear global_costmap"


class ScriptedPlanner(StandIns):
    """Plan number i fails with ``codes[i]`` (0: succeeds; past the list: succeeds).
    Following succeeds once ``plans_before_arrival`` plans were made (never when None)."""

    def __init__(self, codes: list[int], plans_before_arrival: int | None = 1) -> None:
        super().__init__()
        self.codes = codes
        self.plans_before_arrival = plans_before_arrival
        self.planned = threading.Condition()

    def _plan(self, handle: Any) -> ComputePathToPose.Result:
        with self.planned:
            self.events.append("plan")
            code = self.codes[self.plans] if self.plans < len(self.codes) else 0
            self.plans += 1
            self.planned.notify_all()
        if code:
            handle.abort()
            return ComputePathToPose.Result(error_code=code, error_msg=f"stand-in code {code}")
        handle.succeed()
        return ComputePathToPose.Result(path=_path(handle.request.goal.pose.position.x))

    def _follow(self, handle: Any) -> FollowPath.Result:
        self.events.append("follow")
        self.follow_goals += 1
        arrival = self.plans_before_arrival
        deadline = time.monotonic() + 60.0
        arrived = False
        while not handle.is_cancel_requested and handle.is_active and not arrived:
            if time.monotonic() > deadline:
                break
            with self.planned:  # woken by a plan; a cancel is looked at every 0.1 s
                arrived = self.planned.wait_for(
                    lambda: arrival is not None and self.plans >= arrival, timeout=0.1
                )
        if handle.is_cancel_requested:
            handle.canceled()
        elif arrived and handle.is_active:
            handle.succeed()
        else:
            handle.abort()
        return FollowPath.Result()


def _run(supervisor: Any, planner: ScriptedPlanner) -> Any:
    try:
        return navigate(supervisor, planner)
    finally:
        planner.close()


def test_a_first_plan_with_no_path_clears_the_global_costmap_and_plans_again(supervisor):
    planner = ScriptedPlanner([NO_VALID_PATH])
    outcome = _run(supervisor, planner)
    assert outcome.status == SUCCEEDED, (outcome.status, planner.events)
    assert planner.events[:3] == ["plan", CLEAR_GLOBAL, "plan"], planner.events


def test_a_replan_with_no_path_clears_the_global_costmap_and_the_goal_goes_on(supervisor):
    # The first plan works; the first replan (while driving) fails once, its retry works.
    planner = ScriptedPlanner([0, NO_VALID_PATH], plans_before_arrival=4)
    outcome = _run(supervisor, planner)
    assert outcome.status == SUCCEEDED, (outcome.status, planner.events)
    second = planner.events.index("plan", planner.events.index("follow"))
    assert planner.events[second : second + 3] == ["plan", CLEAR_GLOBAL, "plan"], planner.events


def test_replans_that_never_find_a_path_abort_with_the_planners_code(supervisor):
    # Each failing replan is tried twice, with a clear between; three in a row end the goal.
    planner = ScriptedPlanner([0] + [NO_VALID_PATH] * 20, plans_before_arrival=None)
    outcome = _run(supervisor, planner)
    assert outcome.status == ABORTED, (outcome.status, planner.events)
    assert outcome.result.error_code == NO_VALID_PATH, outcome.result.error_msg
    assert planner.plans == 1 + 3 * 2, planner.events
    assert planner.events.count(CLEAR_GLOBAL) == 3, planner.events


def test_a_goal_in_an_obstacle_fails_at_once_without_clearing(supervisor):
    # GOAL_OCCUPIED is not a code a planner recovery helps with (WouldAPlannerRecoveryHelp).
    planner = ScriptedPlanner([GOAL_OCCUPIED] * 5)
    outcome = _run(supervisor, planner)
    assert outcome.status == ABORTED, (outcome.status, planner.events)
    assert outcome.result.error_code == GOAL_OCCUPIED, outcome.result.error_msg
    assert planner.events == ["plan"], planner.events
