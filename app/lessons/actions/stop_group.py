"""Step action ``stop_group``: stop every node of a catalog group."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app import catalog
from app.lessons.registry import register_action

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "stop_group", required="group", optional="label", words="stop every node of a catalog group"
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    group = catalog.lookup_group(action["group"])
    for member in group.members:
        rt.supervisor.stop(member)
    return f"Stopping {', '.join(group.members)}."
