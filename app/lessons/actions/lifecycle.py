"""Step action ``lifecycle``: ask a lifecycle node for a transition."""

from __future__ import annotations

from typing import TYPE_CHECKING

from lifecycle_msgs.srv import ChangeState, GetState

from app.lessons.registry import register_action
from app.ros import lifecycle
from app.ros.calls import STEP_ANSWER_SEC

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "lifecycle",
    required="node transition",
    optional="label",
    words="ask a lifecycle node for a transition and wait (briefly) for its answer",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    request = lifecycle.change_request(action["transition"])
    # Wait for the answer: a step's "configure" then "activate" must happen in that order.
    asked = f"Asked {action['node']} to {action['transition']}"
    response = rt.services.call(f"{action['node']}/change_state", ChangeState, request)
    if response is None:
        return f"{asked}; no answer within {STEP_ANSWER_SEC:g} s (it may be busy)."
    if not getattr(response, "success", False):
        state = rt.services.call(f"{action['node']}/get_state", GetState, GetState.Request())
        label = getattr(getattr(state, "current_state", None), "label", "")
        where = f"it is {label}" if label else "its current state"
        return f"{asked}: it refused ({where}, and {action['transition']} does not start there)."
    return f"{asked}: done."
