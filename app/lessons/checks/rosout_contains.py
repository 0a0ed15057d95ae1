"""Check ``rosout_contains``: the node logged the text on /rosout."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "rosout_contains",
    required="node text",
    optional="at_least",
    words="the node logged the text on /rosout",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    """A node's log message reached /rosout (what rqt_console and the Logs tab read)."""
    if not rt.graph.has_node(c["node"]):
        return CheckResult(FAIL, f"{c['node']} is not on the graph")
    logger = c["node"].strip("/").replace("/", ".")  # rcl names a node's logger so
    tap = rt.tap("/rosout", "rcl_interfaces/msg/Log", history=True)
    needed = c.get("at_least", 1)
    count = 0
    for _, log in tap.newest():
        count += log.name == logger and c["text"] in log.msg
        if count >= needed:
            return CheckResult(PASS, f"{c['node']} logged {c['text']!r} on /rosout")
    return CheckResult(
        WAITING,
        f"{count} of {needed} messages from {c['node']} on /rosout contain {c['text']!r}",
    )
