"""Probe ``action_goal``: send a goal (and maybe cancel it); judge status, feedback, result."""

from __future__ import annotations

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
    goal_run = GoalRun(action, type_text, goal)
    name = f"action {action}" + (" (cancel)" if cancel_after else "")

    def on_feedback(_msg: object) -> None:
        if cancel_after and len(goal_run.feedback) == cancel_after:
            goal_run.cancel()

    try:
        send_goal(ctx.call, goal_run, on_feedback)
    except Ros2Error as exc:
        return Result(name, False, str(exc))
    status = goal_run.status.lower()
    want = "canceled" if cancel_after else p.get("status", "succeeded")
    goal_text = values_text(goal_values)
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
