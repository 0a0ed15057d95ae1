"""Step action ``set_param``: set a parameter on a node."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from rcl_interfaces.srv import SetParameters

from app.lessons.registry import register_action
from app.ros import params

if TYPE_CHECKING:
    from rclpy.task import Future

    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "set_param", required="node name value", optional="label", words="set a parameter on a node"
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    request = params.set_request(action["name"], action["value"])
    client = rt.services.client(f"{action['node']}/set_parameters", SetParameters)
    rt.changed_at = time.monotonic()  # until the node answers, from the click

    def answered(_future: Future) -> None:
        # From now on the node runs with the new value: a rate judged later hears only it.
        rt.changed_at = time.monotonic()

    client.call_async(request).add_done_callback(answered)
    return f"Set {action['name']} = {action['value']!r} on {action['node']}."
