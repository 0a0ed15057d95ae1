"""Step action ``call_service``: call a service with a request."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import register_action
from app.ros.calls import STEP_ANSWER_SEC
from app.ros.convert import fill, import_type

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "call_service",
    required="service type request",
    optional="label",
    words="call a service with a request and wait (briefly) for its answer",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    srv_type = import_type(action["type"])
    request = fill(srv_type.Request, action["request"])
    # Wait for the answer: the step's next button (a drive after a reset) comes after it.
    if rt.services.call(action["service"], srv_type, request) is not None:
        return f"Called {action['service']}: it answered."
    return f"Called {action['service']}; no answer within {STEP_ANSWER_SEC:g} s (it may be busy)."
