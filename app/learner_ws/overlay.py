"""`source install/setup.bash`, understood: a workspace's install space over the underlay.

In a terminal, sourcing a colcon workspace puts each of its package prefixes
(``install/<pkg>``) in front of ``AMENT_PREFIX_PATH``, their Python folders in
front of ``PYTHONPATH`` and their libraries in front of ``LD_LIBRARY_PATH``;
what was there before (the ROS install, here the ROS wheels and the catalog's
prefixes) is the *underlay*. Here the dashboard keeps that list for its
Console, takes a snapshot of the install space when it is sourced (a package
built later needs another ``source``, as in a terminal), and gives every
program started from the Console the same variables.
"""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Iterable, Mapping
from pathlib import Path

PREFIX_ENV = "AMENT_PREFIX_PATH"
INDEX = Path("share/ament_index/resource_index/packages")

_lock = threading.Lock()
_overlay: list[Path] = []  # package prefixes of sourced workspaces, newest first
_sourced: list[Path] = []  # the install folders sourced, newest first
_underlay: list[Path] | None = None


def install_prefixes(install: Path) -> list[Path]:
    """The prefixes a colcon install space adds: install/ (merged) or install/<pkg>/."""
    layout = install / ".colcon_install_layout"
    try:
        merged = layout.read_text(encoding="utf-8").strip() == "merged"
    except OSError:
        merged = False
    if merged:
        return [install]
    return sorted(
        child for child in install.iterdir()
        if child.is_dir() and (child / INDEX / child.name).is_file()
    )  # fmt: skip


def _paths(text: str | None) -> list[Path]:
    return [Path(p) for p in (text or "").split(os.pathsep) if p]


def set_underlay(prefixes: Iterable[Path]) -> None:
    """What the Console sees before any `source`: the ROS wheels and the catalog's prefixes."""
    global _underlay
    with _lock:
        _underlay = list(dict.fromkeys(prefixes))


def underlay() -> list[Path]:
    with _lock:
        if _underlay is not None:
            return list(_underlay)
    return _paths(os.environ.get(PREFIX_ENV)) or [Path(sys.prefix)]


def overlay() -> list[Path]:
    with _lock:
        return list(_overlay)


def sourced() -> list[Path]:
    with _lock:
        return list(_sourced)


def source(install: Path) -> list[Path]:
    """Put ``install``'s prefixes in front (again, if it was sourced before); returns them."""
    prefixes = install_prefixes(install)
    with _lock:
        _overlay[:] = prefixes + [p for p in _overlay if p not in prefixes]
        _sourced[:] = [install] + [p for p in _sourced if p != install]
    # This process's own index lookups (`ros2 interface show`) see it too.
    os.environ[PREFIX_ENV] = os.pathsep.join(str(p) for p in search_path())
    return prefixes


def forget() -> None:
    """A fresh Console: nothing sourced."""
    with _lock:
        _overlay.clear()
        _sourced.clear()
    os.environ[PREFIX_ENV] = os.pathsep.join(str(p) for p in search_path())


def search_path() -> list[Path]:
    """AMENT_PREFIX_PATH as the Console sees it: overlays first, then the underlay."""
    return list(dict.fromkeys([*overlay(), *underlay()]))


def packages() -> dict[str, Path]:
    """Every package of the index, with the first prefix that has it (overlays win)."""
    found: dict[str, Path] = {}
    for prefix in search_path():
        try:
            names = sorted(entry.name for entry in os.scandir(prefix / INDEX) if entry.is_file())
        except OSError:
            continue
        for name in names:
            found.setdefault(name, prefix)
    return found


def package_prefix(name: str) -> Path | None:
    for prefix in search_path():
        if (prefix / INDEX / name).is_file():
            return prefix
    return None


def executables(name: str, prefix: Path) -> list[Path]:
    """Executable files under ``<prefix>/lib/<name>/`` (hidden folders skipped), sorted."""
    found: list[Path] = []
    for folder, subfolders, files in os.walk(prefix / "lib" / name):
        subfolders[:] = sorted(d for d in subfolders if not d.startswith("."))
        for file_name in sorted(files):
            path = Path(folder) / file_name
            if os.access(path, os.X_OK) and path.is_file():
                found.append(path)
    return found


def _python_dirs(prefix: Path) -> list[Path]:
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    return [
        p for p in (prefix / "lib" / version / "site-packages",
                    prefix / "local" / "lib" / version / "dist-packages")
        if p.is_dir()
    ]  # fmt: skip


_PREPEND = ("prepend-non-duplicate", "prepend-non-duplicate-if-exists")
MAX_HOOKS = 64  # dsv files followed per package (a loop of `source` lines ends here)


def hook_paths(prefix: Path) -> dict[str, list[str]]:
    """What colcon's package hooks prepend, per variable: ``share/<pkg>/package.dsv``.

    colcon writes each package's environment changes as ``.dsv`` lines
    (``prepend-non-duplicate;PYTHONPATH;lib/python3.11/site-packages``) and the
    shell scripts that ``setup.bash`` sources follow them; a `--symlink-install`
    Python package adds its ``build/<pkg>`` folder to PYTHONPATH this way. This
    reads the same lines (never running a script) for the packages of ``prefix``.
    """
    found: dict[str, list[str]] = {}
    index = prefix / INDEX
    names = sorted(p.name for p in index.iterdir()) if index.is_dir() else []
    for name in names:
        mine: dict[str, list[str]] = {}
        todo = [prefix / "share" / name / "package.dsv"]
        seen: set[Path] = set()
        while todo and len(seen) < MAX_HOOKS:
            dsv = todo.pop(0)
            if dsv in seen or dsv.suffix != ".dsv":
                continue
            seen.add(dsv)
            try:
                lines = dsv.read_text(encoding="utf-8").splitlines()
            except (OSError, UnicodeDecodeError):
                continue
            for line in lines:
                kind, _, rest = line.partition(";")
                if kind == "source":
                    path = Path(rest) if os.path.isabs(rest) else prefix / rest
                    todo.append(path)
                    continue
                variable, _, values = rest.partition(";")
                if kind not in _PREPEND or not variable:
                    continue
                for value in values.split(";") or [""]:
                    path = (
                        Path(value)
                        if os.path.isabs(value)
                        else (prefix / value if value else prefix)
                    )
                    if kind.endswith("-if-exists") and not path.exists():
                        continue
                    mine.setdefault(variable, []).append(str(path))
        for variable, texts in mine.items():  # each prepend goes in front of the ones before
            for text in reversed(texts):
                if text not in found.setdefault(variable, []):
                    found[variable].append(text)
    return found


def _sourced_paths(variable: str) -> list[str]:
    """``variable``'s folders from the sourced workspaces' hooks, newest overlay first."""
    paths: list[str] = []
    for prefix in overlay():
        hooks = hook_paths(prefix)
        fallback = {
            "PYTHONPATH": [str(d) for d in _python_dirs(prefix)],
            "LD_LIBRARY_PATH": [str(prefix / "lib")] if (prefix / "lib").is_dir() else [],
            "PATH": [str(prefix / "bin")] if (prefix / "bin").is_dir() else [],
        }
        for path in hooks.get(variable) or fallback.get(variable, []):
            if path not in paths:
                paths.append(path)
    return paths


def python_paths() -> list[Path]:
    """The Python folders of the sourced workspaces, newest first (the code editor's Jedi
    finds the learner's messages and modules there)."""
    return [Path(p) for p in _sourced_paths("PYTHONPATH")]


def child_env(base: Mapping[str, str] | None = None) -> dict[str, str]:
    """The variables a sourced shell would hand a program it starts (only those four)."""
    base = os.environ if base is None else base
    python = _sourced_paths("PYTHONPATH")
    libs = _sourced_paths("LD_LIBRARY_PATH")
    bins = _sourced_paths("PATH")

    def joined(front: list[str], name: str) -> str:
        rest = [p for p in base.get(name, "").split(os.pathsep) if p and p not in front]
        return os.pathsep.join(list(dict.fromkeys(front)) + rest)

    return {
        PREFIX_ENV: os.pathsep.join(str(p) for p in search_path()),
        "PYTHONPATH": joined(python, "PYTHONPATH"),
        "LD_LIBRARY_PATH": joined(libs, "LD_LIBRARY_PATH"),
        "PATH": joined(bins, "PATH"),
    }
