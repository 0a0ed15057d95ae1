"""The code a step is about, for the stage's code window.

Most steps show the project's own tutorial nodes (the step's ``code``, else the
lesson's).
A step that writes, edits or checks a source file of the learner's own
workspace (``workspace_write``, ``workspace_edit``, ``workspace_file`` under
``src/``) is about that file: the window shows it as it is on disk now, so
the learner sees the line a button just fixed, or that it is not there yet.
"""

from __future__ import annotations

import html

from app import PROJECT_ROOT
from app.launch import PACKAGE, launch_file_text
from app.learner_ws import folder
from app.lessons.schema import LAUNCH_CODE, Lesson, Step
from app.ros.errors import Ros2Error
from app.ui.code_view import python_listing

WORKSPACE_KINDS = ("workspace_write", "workspace_edit", "workspace_file")
MAX_SHOWN_BYTES = 64_000  # a generated or pasted giant is cut, never sent whole


def workspace_sources(step: Step) -> tuple[str, ...]:
    """The workspace source files the step's buttons and checks name, in their order."""
    paths = (spec.get("path", "") for spec in (*step.actions, *step.checks))
    kinds = (spec.kind for spec in (*step.actions, *step.checks))
    found = [p for p, kind in zip(paths, kinds, strict=True) if kind in WORKSPACE_KINDS]
    return tuple(dict.fromkeys(p for p in found if p.startswith("src/")))


def listing(lesson: Lesson, step: Step) -> str:
    """The HTML of the code window for this step."""
    own = workspace_sources(step)
    if own:
        return "".join(_workspace_file(relative) for relative in own)
    parts = [_project_file(relative) for relative in step.code or lesson.code]
    return "".join(parts) or "<p><em>This lesson shows no code.</em></p>"


def _project_file(relative: str) -> str:
    launch = LAUNCH_CODE.fullmatch(relative)
    if launch is not None:  # written for `ros2 launch`, from the catalog's group
        name = f"{PACKAGE}/launch/{launch['group']}.launch.py"
        return python_listing(name, launch_file_text(launch["group"]), name)
    return python_listing(relative, (PROJECT_ROOT / relative).read_text(encoding="utf-8"), relative)


def _workspace_file(relative: str) -> str:
    ws = folder.current()
    if ws is None:
        return _note(f"{relative}: no learner workspace here")
    try:
        path = ws.confine(relative)
        shown = ws.shown(path)
        with path.open("rb") as file:
            raw = file.read(MAX_SHOWN_BYTES + 1)
    except FileNotFoundError:
        return _note(f"{ws.shown(ws.root / relative)}: not written yet (this step writes it)")
    except (OSError, Ros2Error) as exc:  # a folder, a link out of the workspace, ...
        return _note(f"{relative}: cannot be shown ({exc})")
    text = raw[:MAX_SHOWN_BYTES].decode("utf-8", errors="replace")
    if len(raw) > MAX_SHOWN_BYTES:
        text += "\n… (cut here: the file is longer)"
    return python_listing(f"Your workspace: {shown}", text, path.name)


def _note(text: str) -> str:
    return f'<p style="margin:6px 0"><em>{html.escape(text)}.</em></p>'
