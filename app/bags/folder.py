"""Where bags live: one folder, relative names resolve inside it.

The real `ros2 bag` writes into the current directory. A browser has none,
so the dashboard keeps every bag in one folder (``var/bags`` beside
``var/progress``, or ``$ROS2_CLASSROOM_BAGS``); absolute paths are used as given.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from app import PROJECT_ROOT
from app.bags.errors import BagError

ENV_VAR = "ROS2_CLASSROOM_BAGS"
DEFAULT_DIR = PROJECT_ROOT / "var" / "bags"


def bags_dir() -> Path:
    return Path(os.environ.get(ENV_VAR) or DEFAULT_DIR)


def default_bag_name(now: float | None = None) -> str:
    """rosbag2's default name: rosbag2_YYYY_MM_DD-HH_MM_SS (local time)."""
    return time.strftime("rosbag2_%Y_%m_%d-%H_%M_%S", time.localtime(now))


class _Policy:
    confined = False  # set once, at start-up, by the dashboard (``confine_to_folder``)


def confine_to_folder() -> None:
    """In the dashboard: a name typed in the browser never reaches outside the bags folder.

    A terminal user may record and read anywhere they can; a browser (maybe
    on another machine) must not write or read the dashboard's other files.
    """
    _Policy.confined = True


def _inside_folder(path: Path) -> Path:
    root = bags_dir().resolve()
    resolved = (root / path).resolve()
    if resolved != root and root not in resolved.parents:
        raise BagError(
            f"'{path}': in the dashboard, bags live in the bags folder; "
            "give a name such as my_bag, not a path outside it"
        )
    return resolved


def output_path(name: str | None) -> Path:
    """Where a new recording goes: -o NAME inside the bags folder, or an absolute path."""
    path = Path(name) if name else Path(default_bag_name())
    if _Policy.confined:
        return _inside_folder(path)
    return path if path.is_absolute() else bags_dir() / path


def existing_path(name: str) -> Path:
    """A bag to read: an absolute or working-directory path if it exists, else in the folder."""
    if _Policy.confined:
        return _inside_folder(Path(name))
    path = Path(name).expanduser()
    if path.is_absolute() or path.exists():
        return path
    return bags_dir() / path


def list_bags(folder: Path | None = None) -> list[Path]:
    """Bag folders (those with a metadata.yaml or a storage file), newest first."""
    root = folder or bags_dir()
    if not root.is_dir():
        return []
    found = [
        p
        for p in root.iterdir()
        if p.is_dir()
        and ((p / "metadata.yaml").exists() or any(p.glob("*.mcap")) or any(p.glob("*.db3")))
    ]
    return sorted(found, key=lambda p: p.stat().st_mtime, reverse=True)
