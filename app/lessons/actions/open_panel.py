"""Step action ``open_panel``: point the learner at a tab."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import register_action

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "open_panel", required="panel", optional="label", words="point the learner at a tab"
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    return f"Open the {action['panel']} tab."
