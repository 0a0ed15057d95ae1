"""Check ``log_contains``: a node's output holds enough lines with the text."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.catalog import UnknownNodeError, lookup
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


def _launched_lines(rt: LessonRuntime, name: str) -> tuple[list[str], bool]:
    """The node's log lines inside ``ros2 launch`` programs, and whether one is running.

    ``ros2 launch tutorial_nodes GROUP.launch.py`` in the Console is one program
    for all its nodes; each node's log line there carries its logger name:
    ``[listener-3] [INFO] [...] [listener2]: I heard: ...``.
    """
    try:
        node_name = lookup(name).node_name
    except UnknownNodeError:
        return [], False
    marker = f"] [{node_name.strip('/').replace('/', '.')}]: "
    lines: list[str] = []
    running = False
    for key, status in rt.supervisor.statuses().items():
        if key.startswith("launch:"):
            lines += [line for line in rt.supervisor.output(key) if marker in line]
            running |= status.active
    return lines, running


@register_check(
    "log_contains",
    required="catalog_node text",
    optional="at_least",
    words="a node's output holds enough lines with the text",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    name = c["catalog_node"]
    launched, launching = _launched_lines(rt, name)
    lines = [line for line in [*rt.supervisor.output(name), *launched] if c["text"] in line]
    needed = c.get("at_least", 1)
    if len(lines) >= needed:
        said = "1 line contains" if len(lines) == 1 else f"{len(lines)} lines contain"
        return CheckResult(PASS, f"{name}'s log: {said} {c['text']!r}")
    if not rt.supervisor.status(name).active and not launching:
        return CheckResult(FAIL, f"{name} is not running")
    return CheckResult(
        WAITING, f"{name}'s log: {len(lines)} of {needed} lines contain {c['text']!r} so far"
    )
