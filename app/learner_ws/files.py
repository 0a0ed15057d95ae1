"""File operations on the learner's workspace for the page: list, create, rename, delete, edit.

Every path comes from the page and goes through ``LearnerWorkspace.confine``:
nothing outside the workspace is touched, and the workspace root itself is
never renamed or deleted. Writes are atomic (``write_atomically``), so a
failing save leaves the previous file.
"""

from __future__ import annotations

import os
import secrets
import shutil
import stat
from dataclasses import dataclass
from pathlib import Path

from app.learner_ws.folder import LearnerWorkspace, OutsideWorkspace
from app.ros.errors import Ros2Error

MAX_TEXT_BYTES = 200_000
MAX_LISTED = 300
HIDDEN_IN_TREE = {"build", "install", "log", ".colcon", "__pycache__"}


class FileError(Ros2Error):
    """A file operation the page asked for that cannot be done; one line for the learner."""


NEW_FILE_MODE = 0o644  # as an editor writes under the usual umask: builds (any uid) read it
_DIR_FLAGS = os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC


def _check_inside(ws: LearnerWorkspace, fd: int, shown: str) -> None:
    """The object ``fd`` opened really is inside the workspace (closes it if not).

    ``confine`` resolved the path a moment ago; on a served dashboard the
    learner's contained code may swap a folder of build/ for a link meanwhile.
    The kernel's name for what was actually opened settles it.
    """
    real = Path(os.readlink(f"/proc/self/fd/{fd}"))
    root = ws.root.resolve()
    if real != root and root not in real.parents:
        os.close(fd)
        raise OutsideWorkspace(f"{shown}: outside your workspace (a link changed under it)")


def write_atomically(ws: LearnerWorkspace, path: Path, text: str) -> None:
    """Temporary file, fsync, rename, all through a checked folder descriptor.

    A reader sees the old text or the new, never half; no link swapped in can
    redirect the write. The file keeps its mode (an executable script stays
    executable); a new file gets ``NEW_FILE_MODE``, not mkstemp's 0600.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    folder = os.open(path.parent, _DIR_FLAGS)
    _check_inside(ws, folder, ws.shown(path))
    try:
        try:
            info = os.stat(path.name, dir_fd=folder, follow_symlinks=False)
            mode = stat.S_IMODE(info.st_mode) if stat.S_ISREG(info.st_mode) else NEW_FILE_MODE
        except FileNotFoundError:
            mode = NEW_FILE_MODE
        temporary = f".{path.name}-{secrets.token_hex(4)}"
        flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC
        fd = os.open(temporary, flags, mode, dir_fd=folder)
        try:
            os.fchmod(fd, mode)  # not narrowed by the umask
            with os.fdopen(fd, "w", encoding="utf-8") as handle:
                handle.write(text)
                handle.flush()
                os.fsync(handle.fileno())
            os.replace(temporary, path.name, src_dir_fd=folder, dst_dir_fd=folder)
        except BaseException:
            try:
                os.unlink(temporary, dir_fd=folder)
            except OSError:
                pass
            raise
        os.fsync(folder)
    finally:
        os.close(folder)


def tree(ws: LearnerWorkspace, limit: int = MAX_LISTED) -> list[str]:
    """The workspace as indented lines (folders end with '/'); colcon's output folders folded."""
    root = ws.root
    lines: list[str] = []
    for folder, subfolders, files in os.walk(root):
        depth = len(Path(folder).relative_to(root).parts)
        folded = sorted(d for d in subfolders if depth == 0 and d in HIDDEN_IN_TREE)
        subfolders[:] = sorted(
            d for d in subfolders if not (depth == 0 and d in HIDDEN_IN_TREE) and d[0] != "."
        )
        if depth:
            lines.append("  " * (depth - 1) + Path(folder).name + "/")
        for name in folded:
            lines.append(f"{name}/ (colcon's; not listed)")
        lines += ["  " * depth + name for name in sorted(files)]
        if len(lines) >= limit:
            return lines[:limit] + [f"... (more than {limit} entries)"]
    return lines


@dataclass(frozen=True)
class Entry:
    """One row of a folder listing: its workspace-relative path, and whether it is a folder."""

    path: str
    folder: bool
    note: str = ""  # e.g. colcon's output folders


def relative(ws: LearnerWorkspace, text: str) -> str:
    """The confined path of ``text`` relative to the workspace root (``src/pkg/setup.py``)."""
    path = _inside(ws, text)
    return path.relative_to(ws.root.resolve()).as_posix()


def children(ws: LearnerWorkspace, text: str = "", limit: int = MAX_LISTED) -> list[Entry]:
    """One folder's entries, folders first, hidden names (``.x``) left out; at most ``limit``.

    A lazy tree for the code editor: a workspace of thousands of files costs
    one folder at a time, never a walk of the whole tree.
    """
    folder = ws.confine(text) if text else ws.root.resolve()
    if not folder.is_dir():
        raise FileError(f"{text}: not a folder")
    root = ws.root.resolve()
    found: list[Entry] = []
    with os.scandir(folder) as scan:
        items = sorted(
            (e for e in scan if not e.name.startswith(".")),
            key=lambda e: (not e.is_dir(follow_symlinks=False), e.name),
        )
    for item in items[:limit]:
        path = Path(item.path).relative_to(root).as_posix()
        is_dir = item.is_dir(follow_symlinks=False)
        colcons = is_dir and folder == root and item.name in HIDDEN_IN_TREE
        found.append(Entry(path, is_dir, "colcon's output" if colcons else ""))
    if len(items) > limit:
        found.append(Entry("", False, f"... and {len(items) - limit} more"))
    return found


def _inside(ws: LearnerWorkspace, text: str) -> Path:
    path = ws.confine(text.strip())
    if path == ws.root.resolve():
        raise FileError("that is the workspace itself; name a file or folder inside it")
    return path


def create_file(ws: LearnerWorkspace, text: str) -> Path:
    path = _inside(ws, text)
    if path.exists():
        raise FileError(f"{ws.shown(path)} already exists")
    write_atomically(ws, path, "")
    return path


def create_folder(ws: LearnerWorkspace, text: str) -> Path:
    path = _inside(ws, text)
    if path.exists():
        raise FileError(f"{ws.shown(path)} already exists")
    path.mkdir(parents=True)
    return path


def rename(ws: LearnerWorkspace, old: str, new: str) -> Path:
    source, target = _inside(ws, old), _inside(ws, new)
    if not source.exists():
        raise FileError(f"{old}: no such file or folder")
    if target.exists():
        raise FileError(f"{ws.shown(target)} already exists")
    if target == source or source in target.parents:
        raise FileError("a folder cannot move into itself")
    target.parent.mkdir(parents=True, exist_ok=True)
    source.rename(target)
    return target


def delete(ws: LearnerWorkspace, text: str) -> Path:
    path = _inside(ws, text)
    if path.is_symlink() or path.is_file():
        path.unlink()
    elif path.is_dir():
        shutil.rmtree(path)
    else:
        raise FileError(f"{text}: no such file or folder")
    return path


def read_text(ws: LearnerWorkspace, text: str) -> str:
    path = _inside(ws, text)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except FileNotFoundError:
        raise FileError(f"{text}: not a file") from None
    except OSError as exc:  # a folder, a link swapped in, a fifo...
        raise FileError(f"{text}: not a file ({exc.strerror})") from None
    _check_inside(ws, fd, text)
    with os.fdopen(fd, "rb") as handle:
        info = os.fstat(handle.fileno())
        if not stat.S_ISREG(info.st_mode):
            raise FileError(f"{text}: not a file")
        if info.st_size > MAX_TEXT_BYTES:
            raise FileError(f"{text} is larger than {MAX_TEXT_BYTES // 1000} kB; open it elsewhere")
        data = handle.read(MAX_TEXT_BYTES + 1)
    if b"\x00" in data:
        raise FileError(f"{text} is not a text file")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise FileError(f"{text} is not UTF-8 text") from None


def write_text(ws: LearnerWorkspace, text: str, content: str) -> Path:
    path = _inside(ws, text)
    if len(content.encode("utf-8")) > MAX_TEXT_BYTES:
        raise FileError(f"the text is larger than {MAX_TEXT_BYTES // 1000} kB")
    if path.is_dir():
        raise FileError(f"{text} is a folder")
    write_atomically(ws, path, content)
    return path
