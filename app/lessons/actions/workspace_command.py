"""Step action ``workspace_command``: type a `colcon ...` or `source ...` line into the Console.

The ``console`` kind types `ros2 ...` lines; these two commands are not ros2
verbs but the tutorials type them in the same terminal, and so does the Console.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import register_action
from app.ros.errors import Ros2Error

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

FIRST_WORDS = ("colcon", "source")


@register_action(
    "workspace_command",
    required="command",
    optional="label",
    words="type a `colcon ...` or `source ...` line into the Console tab, as the learner would",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    command = action["command"]
    words = command.split()
    if not words or words[0] not in FIRST_WORDS or "\n" in command:
        raise Ros2Error(f"not a colcon or source line: {command!r}")
    if rt.console is None:
        return f"Type it in the Console tab: {command}"
    rt.console(command)
    return f"Running in the Console tab: {command}"
