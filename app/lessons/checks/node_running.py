"""Check ``node_running``: the node is on the ROS graph."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check("node_running", required="node", words="the node is on the ROS graph")
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    if rt.graph.has_node(c["node"]):
        return CheckResult(PASS, f"{c['node']} is on the graph")
    return CheckResult(FAIL, f"{c['node']} is not on the graph")
