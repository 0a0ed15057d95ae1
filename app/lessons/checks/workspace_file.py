"""Check ``workspace_file``: a file of your workspace exists (and holds a line of text)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.checks._own_workspace import building, workspace
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "workspace_file",
    required="path",
    optional="contains",
    words="a file in your workspace exists and holds the text",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    ws = workspace()
    path = ws.confine(c["path"])
    shown = ws.shown(path)
    generated = path.relative_to(ws.root.resolve()).parts[:1] in (("build",), ("install",))
    if generated and building(rt):
        return CheckResult(WAITING, "colcon is still building")
    if not path.is_file():
        return CheckResult(FAIL, f"{shown} does not exist")
    wanted = c.get("contains")
    if wanted is None:
        return CheckResult(PASS, f"{shown} exists")
    text = path.read_text(encoding="utf-8", errors="replace")
    # Spaces around '=' and the quotes' kind vary between people: compare without them.
    if _squeezed(wanted) in _squeezed(text):
        return CheckResult(PASS, f"{shown} has {wanted!r}")
    return CheckResult(FAIL, f"{shown} does not have {wanted!r} yet")


def _squeezed(text: str) -> str:
    return "".join(text.split()).replace('"', "'")
