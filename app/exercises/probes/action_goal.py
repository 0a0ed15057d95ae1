"""Probe ``action_goal``: send a goal (and maybe cancel it); judge status, feedback, result."""

from __future__ import annotations

from action_msgs.srv import CancelGoal

from app.exercises.probes.base import (
    ProbeContext,
    draw,
    expected_value,
    register_probe,
    same,
    values_text,
)
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros.calls import GoalRun, send_goal
from app.ros.convert import fill, import_type, to_plain
from app.ros.errors import Ros2Error

CANCEL_TRIES = 3
# action_msgs/srv/CancelGoal's answer when the goal had already ended.
GOAL_TERMINATED = CancelGoal.Response.ERROR_GOAL_TERMINATED


def _drive(ctx: ProbeContext, goal_run: GoalRun, cancel_after: int | None) -> None:
    def on_feedback(_msg: object) -> None:
        if cancel_after and len(goal_run.feedback) == cancel_after:
            goal_run.cancel()

    send_goal(ctx.call, goal_run, on_feedback, resend_unanswered=True)


def _cancel_came_too_late(goal_run: GoalRun) -> bool:
    """No answer to the cancel before the result, or the answer "the goal had ended"."""
    return goal_run.cancel_code in (None, GOAL_TERMINATED)


@register_probe(
    "action_goal",
    required="action type goal",
    optional="status min_feedback result_field result_expect cancel_after_feedback",
    words="sends a goal with random fields (and may cancel it after some feedback); judges "
    "the final status, the feedback and the result against the exercise's formula",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    action, type_text = p["action"], p["type"]
    goal_values = {k: draw(ctx.rng, v) for k, v in p["goal"].items()}
    goal = fill(import_type(type_text, "action").Goal, goal_values)
    cancel_after = draw(ctx.rng, p.get("cancel_after_feedback"))
    name = f"action {action}" + (" (cancel)" if cancel_after else "")
    want = "canceled" if cancel_after else p.get("status", "succeeded")
    goal_text = values_text(goal_values)
    for _ in range(CANCEL_TRIES):
        goal_run = GoalRun(action, type_text, goal)
        try:
            _drive(ctx, goal_run, cancel_after)
        except Ros2Error as exc:
            return Result(name, False, str(exc))
        status = goal_run.status.lower()
        if not (cancel_after and status == "succeeded" and _cancel_came_too_late(goal_run)):
            break
        # The server took our cancel only once the goal had ended: a server whose executor
        # is busy in execute() (a single thread), or a machine too slow for the goal's
        # length. Again, cancelling at the first feedback: a slow machine gets more time.
        cancel_after = 1
    else:
        return Result(
            name,
            False,
            f"goal {goal_text}: the action succeeded, expected canceled; {CANCEL_TRIES} times "
            "the server took the cancel request only after the goal had ended (while execute() "
            "runs, its executor must be free to take it)",
        )
    if status != want:
        return Result(name, False, f"goal {goal_text}: the action {status}, expected {want}")
    need, fed = p.get("min_feedback", 0), len(goal_run.feedback)
    if fed < need:
        return Result(
            name, False, f"goal {goal_text}: {fed} feedback messages, expected at least {need}"
        )
    if "result_field" in p.fields and not cancel_after:
        got = to_plain(getattr(goal_run.result, p["result_field"]))
        want_value = expected_value(p["result_expect"], goal_values)
        if not same(got, want_value, 1e-6):
            return Result(
                name,
                False,
                f"goal {goal_text}: result {p['result_field']}={got!r}; expected {want_value!r}",
            )
    return Result(
        name, True, f"goal {goal_text}: {status}, {len(goal_run.feedback)} feedback messages"
    )
