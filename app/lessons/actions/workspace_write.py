"""Step action ``workspace_write``: write a file of the tutorial into your workspace for you.

The lesson's "do it for me" button beside "type it yourself in the file tree":
the file's text is in the lesson, the path stays inside the workspace, and
a file the learner already wrote is kept unless it is the same text.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.checks._own_workspace import workspace
from app.lessons.registry import register_action

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "workspace_write",
    required="path content",
    optional="label replace",
    words="write the tutorial's file into your workspace (your own file is kept)",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    """``replace = true``: overwrite what is there (a file the lesson itself broke on purpose)."""
    ws = workspace()
    path = ws.confine(action["path"])
    shown = ws.shown(path)
    content = action["content"]
    if path.is_file() and not action.get("replace", False):
        if path.read_text(encoding="utf-8", errors="replace") == content:
            return f"{shown} already holds the tutorial's text."
        return f"{shown} exists and is yours: kept as it is (delete it to get the tutorial's)."
    path.parent.mkdir(parents=True, exist_ok=True)  # inside: ``path`` is, resolved
    temporary = path.with_name(f".{path.name}.lesson")
    temporary.write_text(content, encoding="utf-8")
    temporary.replace(path)
    return f"Wrote {shown}: open it in the Console tab's workspace files to read it."
