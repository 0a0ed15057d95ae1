"""Check ``log_contains``: a node's output holds enough lines with the text."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "log_contains",
    required="catalog_node text",
    optional="at_least",
    words="a node's output holds enough lines with the text",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    name = c["catalog_node"]
    lines = [line for line in rt.supervisor.output(name) if c["text"] in line]
    needed = c.get("at_least", 1)
    if len(lines) >= needed:
        return CheckResult(PASS, f"{len(lines)} log lines contain {c['text']!r}")
    if not rt.supervisor.status(name).active:
        return CheckResult(FAIL, f"{name} is not running")
    return CheckResult(WAITING, f"{len(lines)} of {needed} log lines contain {c['text']!r} so far")
