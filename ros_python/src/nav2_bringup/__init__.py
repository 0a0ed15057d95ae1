"""nav2_bringup: Nav2's launch files and parameters file, for our Python Nav2 servers.

``launch/localization_launch.py`` (map_server, amcl), ``launch/navigation_launch.py``
(controller, planner, navigator, waypoint follower) and ``launch/bringup_launch.py``
(both) with Nav2's launch arguments (``map``, ``params_file``, ``namespace``,
``use_sim_time``, ``autostart``, ``use_localization``, ``log_level``), and
``params/nav2_params.yaml`` in Nav2's layout holding what these nodes read.

An installed ROS package keeps such files in its share directory; ``share_files()``
gives them as ``share/nav2_bringup/...`` paths with their text, for an ament prefix
(the catalog's) to hold, so that ``ros2 launch nav2_bringup bringup_launch.py`` and
``get_package_share_directory('nav2_bringup')`` find them.
"""

from __future__ import annotations

from pathlib import Path

PACKAGE = "nav2_bringup"
_HERE = Path(__file__).resolve().parent
SHARED = ("launch", "params")


def source_directory() -> Path:
    """This package's folder: launch/ and params/ as the share directory holds them."""
    return _HERE


def params_file() -> Path:
    """The package's own params/nav2_params.yaml (its source; the share copy is the same)."""
    return _HERE / "params" / "nav2_params.yaml"


def share_files() -> dict[str, str]:
    """``share/nav2_bringup/<folder>/<file>`` -> text, for every launch and params file."""
    files: dict[str, str] = {}
    for folder in SHARED:
        for path in sorted((_HERE / folder).iterdir()):
            if path.is_file() and path.suffix in (".py", ".yaml"):
                files[f"share/{PACKAGE}/{folder}/{path.name}"] = path.read_text(encoding="utf-8")
    return files
