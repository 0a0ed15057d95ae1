"""The action probe's cancel judges the server, not the machine's speed.

When the goal succeeds although it was cancelled, the server's answer to the cancel
says why: "accepted" (it took the cancel and went on: wrong) or "the goal had ended"
(it took the request only afterwards: a single-threaded server, or a machine too slow
for the goal's length). Only the second is tried again, cancelling sooner; three
such answers fail with the reason. Each trial here is scripted: the real server runs
in tests/exercises/test_grading.py (fibonacci_server's reference and mistakes).
"""

from __future__ import annotations

import random

import pytest
from action_msgs.srv import CancelGoal

from app.exercises.probes import action_goal
from app.exercises.probes.base import ProbeContext
from app.lessons.schema import Spec

ACCEPTED = CancelGoal.Response.ERROR_NONE
ENDED = CancelGoal.Response.ERROR_GOAL_TERMINATED
PROBE = Spec(
    "action_goal",
    {
        "action": "/fibonacci_exercise",
        "type": "tutorial_interfaces/action/Fibonacci",
        "goal": {"order": 20},
        "cancel_after_feedback": 3,
    },
)


def grade(monkeypatch, trials: list[tuple[str, int | None]]) -> tuple[bool, str, list[int]]:
    """Run the probe with each trial's final status and cancel answer scripted."""
    script = iter(trials)
    cancelled_at: list[int] = []

    def drive(_ctx, goal_run, cancel_after):
        cancelled_at.append(cancel_after)
        goal_run.status, goal_run.cancel_code = next(script)

    monkeypatch.setattr(action_goal, "_drive", drive)
    ctx = ProbeContext(call=None, learner_node="/fib_server", wait_check=None, rng=random.Random(1))
    result = action_goal.run(ctx, PROBE)
    return result.passed, result.detail, cancelled_at


def test_a_cancel_taken_in_time_passes_at_once(monkeypatch):
    assert grade(monkeypatch, [("CANCELED", ACCEPTED)])[::2] == (True, [3])


def test_a_server_that_accepts_the_cancel_and_goes_on_fails_at_once(monkeypatch):
    passed, detail, tries = grade(monkeypatch, [("SUCCEEDED", ACCEPTED)])
    assert not passed and "expected canceled" in detail and tries == [3]


@pytest.mark.parametrize("answer", [ENDED, None])
def test_a_cancel_taken_too_late_is_tried_again_sooner(monkeypatch, answer):
    passed, _detail, tries = grade(monkeypatch, [("SUCCEEDED", answer), ("CANCELED", ACCEPTED)])
    assert passed and tries == [3, 1]


def test_three_late_cancels_fail_and_say_why(monkeypatch):
    passed, detail, tries = grade(monkeypatch, [("SUCCEEDED", ENDED)] * 3)
    assert not passed and tries == [3, 1, 1]
    assert "expected canceled" in detail and "only after the goal had ended" in detail
