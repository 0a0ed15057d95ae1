"""Where the workspace is, and paths typed in the page confined to it.

A path from the page or the Console is relative to the workspace root
(``src/my_package``), or spelled the tutorials' way (``~/ros2_ws/src``), or
absolute inside the workspace. Whatever resolves outside it, through ``..``
or a symbolic link, is refused with one clear line.
"""

from __future__ import annotations

import errno
import os
import threading
from dataclasses import dataclass
from pathlib import Path

from app.ros.errors import Ros2Error

TUTORIAL_NAME = "~/ros2_ws"  # how the tutorials spell the workspace


class OutsideWorkspace(Ros2Error):
    """A typed path that would leave the learner's workspace."""


@dataclass(frozen=True)
class BuildLimits:
    """Bounds of one `colcon build`: it runs the learner's setup.py and CMake code."""

    seconds: float = 600.0  # an interface package takes 20-60 s on 2 busy cores
    disk_bytes: int = 1024**3  # build/ install/ log/ together
    file_bytes: int = 256 * 1024**2  # any one file the build writes (RLIMIT_FSIZE)


COLCON_FOLDERS = ("build", "install", "log")


@dataclass(frozen=True)
class LearnerWorkspace:
    """One learner's colcon workspace and how builds in it may run."""

    root: Path
    # Served to other machines: builds run learner code, which must then be
    # allowed by the teacher and contained; see app.learner_ws.build.
    remote: bool = False
    limits: BuildLimits = BuildLimits()
    # Served: the group contained builds and nodes run in (app.containment.contain's
    # SANDBOX_GID). They read src/ through it and write only build/, install/, log/.
    group: int | None = None

    @property
    def src(self) -> Path:
        return self.root / "src"

    @property
    def home(self) -> Path:
        """The folder the workspace lives in (served: the learner's scratch folder)."""
        return self.root.parent

    def ensure(self) -> LearnerWorkspace:
        """Create the workspace and its src/ folder: private to the user, or (served) to the
        user and the sandbox group, which may read them but not write them."""
        if self.group is None:
            self.src.mkdir(parents=True, exist_ok=True, mode=0o700)
            return self
        self.src.mkdir(parents=True, exist_ok=True)
        _to_group(self.home, self.group, 0o2770)  # as the sandbox opens a scratch folder
        for folder in (self.root, self.src):
            _to_group(folder, self.group, 0o2750)
        return self

    def colcon_folders(self) -> list[Path]:
        """build/, install/ and log/, made (served: writable by the sandbox group only there)."""
        folders = [self.root / name for name in COLCON_FOLDERS]
        for folder in folders:
            folder.mkdir(exist_ok=True)
            if self.group is not None:
                _to_group(folder, self.group, 0o2770)
        return folders

    def confine(self, text: str) -> Path:
        """The real path of ``text`` inside the workspace, or OutsideWorkspace."""
        if not text or "\x00" in text:
            raise OutsideWorkspace("empty or unreadable path")
        if text == TUTORIAL_NAME or text.startswith(TUTORIAL_NAME + "/"):
            text = text[len(TUTORIAL_NAME) :].lstrip("/") or "."
        elif text.startswith("~"):
            raise OutsideWorkspace(
                f"{text}: outside your workspace (here ~/ros2_ws is your workspace, {self.root})"
            )
        root = self.root.resolve()
        candidate = Path(text) if os.path.isabs(text) else root / text
        resolved = candidate.resolve()  # follows symbolic links: an escape shows here
        if resolved != root and root not in resolved.parents:
            raise OutsideWorkspace(
                f"{text}: outside your workspace {root} (paths stay inside it: no '..' out of "
                "it, no links pointing elsewhere, no absolute paths to other folders)"
            )
        return resolved

    def shown(self, path: Path) -> str:
        """A path as the learner reads it: relative to the workspace."""
        try:
            relative = path.resolve().relative_to(self.root.resolve())
        except ValueError:
            return str(path)
        return f"{TUTORIAL_NAME}/{relative}" if str(relative) != "." else TUTORIAL_NAME


def _to_group(folder: Path, group: int, mode: int) -> None:
    """This one folder (no walk, no link followed) to ``group`` with ``mode``.

    Where the group cannot be given, the folder stays the user's alone: not
    root (EPERM), or a user namespace that does not map the sandbox's ids
    (EINVAL: rootless Podman/Docker, Kubernetes user namespaces). No sandbox
    runs there either (app.containment.contain.missing says why), so contained
    builds are refused; the group bits would only open it to the user's group.
    """
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC)
    try:
        try:
            os.fchown(fd, -1, group)
        except OSError as exc:
            if exc.errno not in (errno.EPERM, errno.EINVAL):
                raise
            mode &= 0o700
        os.fchmod(fd, mode)
    finally:
        os.close(fd)


def default_root(progress_file: Path) -> Path:
    """``<progress dir>/<learner>.ros2_ws``: beside the progress file and the code folder."""
    return progress_file.parent / f"{progress_file.stem}.ros2_ws"


_lock = threading.Lock()
_current: LearnerWorkspace | None = None


def configure(workspace: LearnerWorkspace | None) -> None:
    """The dashboard's learner workspace (None: a terminal, where the working folder rules)."""
    global _current
    with _lock:
        _current = workspace.ensure() if workspace is not None else None


def current() -> LearnerWorkspace | None:
    with _lock:
        return _current
