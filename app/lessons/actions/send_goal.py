"""Step action ``send_goal``: send a goal to an action server (optionally cancelled after
some feedback).
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

from app.lessons.registry import register_action
from app.ros.calls import GoalRun, send_goal
from app.ros.context import CallContext, Limits
from app.ros.convert import fill, import_type
from app.ros.errors import Ros2Error

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

# A goal from a lesson button: wait a little for the server, then up to a minute.
GOAL_LIMITS = Limits(service_timeout=3.0, action_timeout=60.0)


@register_action(
    "send_goal",
    required="action type goal",
    optional="label cancel_after_feedback",
    words="send a goal to an action server (optionally cancelled after some feedback)",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    name, type_text = action["action"], action["type"]
    goal = fill(import_type(type_text, "action").Goal, action["goal"])
    run = GoalRun(name, type_text, goal)
    cancel_after = action.get("cancel_after_feedback")

    def on_feedback(_feedback: object) -> None:
        if cancel_after and len(run.feedback) == cancel_after:
            run.cancel()

    with rt.lock:
        rt.goals[name] = run
    ctx = CallContext(rt.node, limits=GOAL_LIMITS)

    def drive() -> None:
        try:
            send_goal(ctx, run, on_feedback)
        except Ros2Error:
            pass  # recorded in run.error; the check shows it

    threading.Thread(target=drive, name=f"lesson-goal-{name}", daemon=True).start()
    return f"Sent a goal to {name}."
