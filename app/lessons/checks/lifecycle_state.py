"""Check ``lifecycle_state``: the lifecycle node is in the named state."""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

from lifecycle_msgs.srv import GetState

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "lifecycle_state", required="node state", words="the lifecycle node is in the named state"
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    if not rt.graph.has_node(c["node"]):
        return CheckResult(FAIL, f"{c['node']} is not on the graph")
    response = cast(
        "GetState.Response | None",
        rt.services.latest(c.key, f"{c['node']}/get_state", GetState, GetState.Request()),
    )
    if response is None:
        return CheckResult(WAITING, f"asking {c['node']} for its state")
    label = response.current_state.label
    if label == c["state"]:
        return CheckResult(PASS, f"{c['node']} is {label}")
    return CheckResult(FAIL, f"{c['node']} is {label}, not {c['state']}")
