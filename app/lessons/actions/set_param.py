"""Step action ``set_param``: set a parameter on a node."""

from __future__ import annotations

from typing import TYPE_CHECKING

from rcl_interfaces.srv import SetParameters

from app.lessons.registry import register_action
from app.ros import params

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "set_param", required="node name value", optional="label", words="set a parameter on a node"
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    request = params.set_request(action["name"], action["value"])
    rt.services.send(f"{action['node']}/set_parameters", SetParameters, request)
    return f"Set {action['name']} = {action['value']!r} on {action['node']}."
