"""Step action ``console``: type a `ros2 ...` command into the Console tab, as the learner
would.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import register_action

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "console",
    required="command",
    optional="label",
    words="type a `ros2 ...` command into the Console tab, as the learner would",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    command = action["command"]
    if rt.console is None:
        return f"Type it in the Console tab: {command}"
    rt.console(command)
    return f"Running in the Console tab: {command}"
