"""What the workspace checks share: the learner's workspace, or a clear reason it is absent."""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING

from app.learner_ws import build, folder, overlay
from app.learner_ws.folder import LearnerWorkspace
from app.ros.errors import Ros2Error

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime

_PACKAGE = re.compile(r"^[a-z][a-z0-9_]*$")


def workspace() -> LearnerWorkspace:
    """The dashboard's learner workspace; a check without one fails with this reason."""
    ws = folder.current()
    if ws is None:
        raise Ros2Error("no learner workspace here (the dashboard gives each learner ~/ros2_ws)")
    return ws


def building(rt: LessonRuntime) -> bool:
    """A `colcon` typed in the Console is still running: install/ may be half written."""
    return any(
        key.startswith(build.PROGRAM_PREFIX) and status.active
        for key, status in rt.supervisor.statuses().items()
    )


def package_name(text: str) -> str:
    if not _PACKAGE.match(text):
        raise ValueError(f"'{text}' is not a valid ROS package name")
    return text


def installed_prefix(ws: LearnerWorkspace, package: str) -> Path | None:
    """``install/<pkg>`` (or a merged ``install/``) when colcon registered the package there."""
    install = ws.root / "install"
    for prefix in (install / package, install):
        if (prefix / overlay.INDEX / package).is_file():
            return prefix
    return None
