"""Step action ``stop``: stop a catalog node (Ctrl+C first)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import register_action

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "stop", required="catalog_node", optional="label", words="stop a catalog node (Ctrl+C first)"
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    rt.supervisor.stop(action["catalog_node"])
    return f"Stopping {action['catalog_node']}."
