"""The action_result check says why a goal failed when the action's result says it.

A lesson walk (ci98) saw only "the goal aborted, expected succeeded"; Nav2's
results carry an error code and message, which tell a learner (and us) why.
"""

from __future__ import annotations

import threading
from types import SimpleNamespace

from nav2_msgs.action import NavigateToPose

from app.lessons.checks.action_result import evaluate
from app.lessons.registry import FAIL, PASS
from app.ros.calls import GoalRun

ACTION = "/navigate_to_pose"


def _runtime(status: str, result: object) -> SimpleNamespace:
    run = GoalRun(ACTION, "nav2_msgs/action/NavigateToPose", NavigateToPose.Goal())
    run.status, run.result = status, result
    run.done.set()
    return SimpleNamespace(lock=threading.Lock(), goals={ACTION: run})


def test_an_aborted_goal_says_the_servers_error_code_and_message():
    result = NavigateToPose.Result(error_code=208, error_msg="no valid path found")
    check = evaluate(_runtime("ABORTED", result), {"action": ACTION, "status": "succeeded"})
    assert check.state == FAIL
    assert check.reason == ("the goal aborted, expected succeeded (error 208: no valid path found)")


def test_a_code_without_a_message_is_still_told():
    result = NavigateToPose.Result(error_code=105)
    check = evaluate(_runtime("ABORTED", result), {"action": ACTION, "status": "succeeded"})
    assert check.reason.endswith("(error 105)"), check.reason


def test_a_result_that_says_nothing_adds_nothing():
    check = evaluate(
        _runtime("ABORTED", NavigateToPose.Result()), {"action": ACTION, "status": "succeeded"}
    )
    assert check.reason == "the goal aborted, expected succeeded"
    check = evaluate(_runtime("SUCCEEDED", None), {"action": ACTION, "status": "succeeded"})
    assert (check.state, check.reason) == (PASS, "the goal succeeded")
