"""Step action ``start``: start a catalog node."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import register_action

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action("start", required="catalog_node", optional="label", words="start a catalog node")
def perform(rt: LessonRuntime, action: Spec) -> str:
    name = action["catalog_node"]
    status = rt.supervisor.start(name)
    program = rt.supervisor.program(name)
    # The button says what was run, the checks the node it made: the message ties the two.
    node = f": node {program.node_name}" if program is not None else ""
    return f"Started {name}{node} (pid {status.pid})."
