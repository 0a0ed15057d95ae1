"""Step action ``stop_own``: stop a node of yours started with `ros2 run` (Ctrl+C first)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import register_action
from app.supervisor import own_program_key

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

STOP_WAIT_SEC = 20.0  # above the supervisor's SIGINT -> SIGTERM -> SIGKILL escalation


@register_action(
    "stop_own",
    required="package executable",
    optional="label",
    words="stop a node of yours that `ros2 run PACKAGE EXECUTABLE` started (Ctrl+C first)",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    key = own_program_key(action["package"], action["executable"])
    shown = f"{action['package']} {action['executable']}"
    status = rt.supervisor.statuses().get(key)
    if status is None or not status.active:
        return f"{shown} is not running."
    rt.supervisor.stop(key).result(timeout=STOP_WAIT_SEC)
    return f"Stopped {shown}."
