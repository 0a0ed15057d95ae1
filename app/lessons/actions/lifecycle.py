"""Step action ``lifecycle``: ask a lifecycle node for a transition."""

from __future__ import annotations

from typing import TYPE_CHECKING

from lifecycle_msgs.srv import ChangeState

from app.lessons.registry import register_action
from app.ros import lifecycle

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "lifecycle",
    required="node transition",
    optional="label",
    words="ask a lifecycle node for a transition",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    request = lifecycle.change_request(action["transition"])
    rt.services.send(f"{action['node']}/change_state", ChangeState, request)
    return f"Asked {action['node']} to {action['transition']}."
