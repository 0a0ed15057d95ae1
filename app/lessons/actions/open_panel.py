"""Step action ``open_panel``: bring a tool into view beside the step.

The lessons panel opens the tool's tab in the page when the button is
clicked (``LessonsPanel``'s ``open_tool``); the message says where the tool
lives, so the learner finds it again on their own.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import register_action
from app.ui import GROUP_OF

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "open_panel", required="panel", optional="label", words="bring a tool's tab into view"
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    tool = action["panel"]
    group = GROUP_OF.get(tool)
    where = f"{group} › {tool}" if group else tool
    return f"{tool} is open below: {where}. The step's text is in Learn › Lessons."
