"""Check ``own_node``: a node of yours, started by `ros2 run` or `ros2 launch`, is on the graph."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check
from app.supervisor import OWN_PROGRAM

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

_NAME = re.compile(r"^(/[A-Za-z_][A-Za-z0-9_]*)+$")
# The Console's programs for the learner's own code: `ros2 run` of a sourced
# package ("own:/pkg/exe") and `ros2 launch` ("launch:pkg/file").
OWN_PREFIXES = (OWN_PROGRAM, "launch:")


@register_check(
    "own_node",
    required="ros_node",
    optional="text at_least",
    words=(
        "a node of yours (started from the Console with ros2 run or ros2 launch) is on the "
        "graph, and its log says the text"
    ),
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    name = c["ros_node"]
    if not _NAME.match(name):
        raise ValueError(f"'{name}' is not a ROS node name such as /minimal_publisher")
    running = [
        key for key, status in rt.supervisor.statuses().items()
        if key.startswith(OWN_PREFIXES) and status.active
    ]  # fmt: skip
    if not running:
        return CheckResult(FAIL, "none of your own programs runs (ros2 run or ros2 launch one)")
    if not rt.graph.has_node(name):
        return CheckResult(FAIL, f"{name} is not on the graph")
    text = c.get("text")
    if text is None:
        return CheckResult(PASS, f"{name} is on the graph")
    # rclpy's log lines name the logger: "[INFO] [1700000000.1] [minimal_subscriber]: ..."
    marker = f"[{name.strip('/').replace('/', '.')}]: "
    lines = [
        line for key in running for line in rt.supervisor.output(key)
        if marker in line and text in line
    ]  # fmt: skip
    needed = c.get("at_least", 1)
    if len(lines) >= needed:
        return CheckResult(PASS, f"{name} logged {len(lines)} lines with {text!r}")
    return CheckResult(WAITING, f"{name} logged {len(lines)} of {needed} lines with {text!r}")
