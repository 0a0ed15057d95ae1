"""Step action ``start_group``: start every node of a catalog group."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app import catalog
from app.lessons.registry import register_action

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "start_group", required="group", optional="label", words="start every node of a catalog group"
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    group = catalog.lookup_group(action["group"])
    for member in group.members:
        rt.supervisor.start(member)
    return f"Started {', '.join(group.members)}."
