"""Check ``node_absent``: the node has left the ROS graph."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check("node_absent", required="node", words="the node has left the ROS graph")
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    if rt.graph.has_node(c["node"]):
        return CheckResult(FAIL, f"{c['node']} is still on the graph")
    return CheckResult(PASS, f"{c['node']} is gone")
