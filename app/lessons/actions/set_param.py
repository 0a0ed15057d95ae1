"""Step action ``set_param``: set a parameter on a node."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from rcl_interfaces.srv import SetParameters

from app.lessons.registry import register_action
from app.ros import params
from app.ros.calls import STEP_ANSWER_SEC

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "set_param",
    required="node name value",
    optional="label",
    words="set a parameter on a node and wait (briefly) for its answer",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    request = params.set_request(action["name"], action["value"])
    rt.changed_at = time.monotonic()  # until the node answers, from the click
    said = f"Set {action['name']} = {action['value']!r} on {action['node']}"
    # Wait for the answer: the step's next button finds the node running with the value.
    response = rt.services.call(f"{action['node']}/set_parameters", SetParameters, request)
    if response is None:
        return f"{said}; no answer within {STEP_ANSWER_SEC:g} s (it may be busy)."
    # From now on the node runs with the new value: a rate judged later hears only it.
    rt.changed_at = time.monotonic()
    results = getattr(response, "results", [])
    if results and not results[0].successful:
        return f"{said}: it refused: {results[0].reason or 'no reason given'}."
    return f"{said}: done."
