"""Check ``parameter_equals``: the node's parameter has the value."""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

from rcl_interfaces.srv import GetParameters

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check
from app.ros import params

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "parameter_equals", required="node name value", words="the node's parameter has the value"
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    if not rt.graph.has_node(c["node"]):
        return CheckResult(FAIL, f"{c['node']} is not on the graph")
    request = GetParameters.Request(names=[c["name"]])
    response = cast(
        "GetParameters.Response | None",
        rt.services.latest(c.key, f"{c['node']}/get_parameters", GetParameters, request),
    )
    if response is None:
        return CheckResult(WAITING, f"asking {c['node']} for {c['name']}")
    if not response.values:
        return CheckResult(FAIL, f"{c['node']} has no parameter {c['name']}")
    value = params.python_value(response.values[0])
    expected = c["value"]
    if params.same_value(value, expected):
        return CheckResult(PASS, f"{c['name']} = {value!r}")
    return CheckResult(FAIL, f"{c['name']} = {value!r}, expected {expected!r}")
