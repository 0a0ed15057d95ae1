"""Step action ``workspace_edit``: make one edit of the tutorial in a file of your workspace."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.checks._own_workspace import workspace
from app.lessons.registry import register_action
from app.ros.errors import Ros2Error

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "workspace_edit",
    required="path old new",
    optional="label",
    words="replace a piece of a file in your workspace, as the tutorial edits it",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    ws = workspace()
    path = ws.confine(action["path"])
    shown = ws.shown(path)
    if not path.is_file():
        raise Ros2Error(f"{shown} does not exist yet (an earlier step creates it)")
    text = path.read_text(encoding="utf-8")
    old, new = action["old"], action["new"]
    if new in text:
        return f"{shown} already has this edit."
    if old not in text:
        raise Ros2Error(
            f"{shown} no longer has the text this edit replaces ({old.strip()[:60]!r}): "
            "you changed it yourself; make the edit by hand as the step says"
        )
    temporary = path.with_name(f".{path.name}.lesson")
    temporary.write_text(text.replace(old, new, 1), encoding="utf-8")
    temporary.replace(path)
    return f"Edited {shown}."
