"""Step action ``start``: start a catalog node."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import register_action

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action("start", required="catalog_node", optional="label", words="start a catalog node")
def perform(rt: LessonRuntime, action: Spec) -> str:
    status = rt.supervisor.start(action["catalog_node"])
    return f"Started {action['catalog_node']} (pid {status.pid})."
