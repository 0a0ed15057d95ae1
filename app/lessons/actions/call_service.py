"""Step action ``call_service``: call a service with a request."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import register_action
from app.ros.convert import fill, import_type

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "call_service",
    required="service type request",
    optional="label",
    words="call a service with a request",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    srv_type = import_type(action["type"])
    request = fill(srv_type.Request, action["request"])
    rt.services.send(action["service"], srv_type, request)
    return f"Called {action['service']}."
