"""nav2_bringup's files as an installed package would hold them, and its yaml flattened."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

PARAMETERS = "ros__parameters"


def bringup_prefix(root: Path) -> Path:
    """An ament prefix holding only nav2_bringup (its share folder and index marker)."""
    from nav2_bringup import share_files

    for relative, text in {
        **share_files(),
        "share/ament_index/resource_index/packages/nav2_bringup": "",
    }.items():
        path = root / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return root


def flatten(table: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested parameter names as ROS spells them: ``FollowPath.desired_linear_vel``."""
    out: dict[str, Any] = {}
    for key, value in table.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten(value, name + "."))
        else:
            out[name] = value
    return out


def node_sections(document: dict[str, Any], namespace: str = "") -> dict[str, dict[str, Any]]:
    """Fully qualified node name -> its flattened parameters, for every section of the file."""
    out: dict[str, dict[str, Any]] = {}
    for key, value in document.items():
        if not isinstance(value, dict):
            continue
        if PARAMETERS in value:
            out[f"{namespace}/{key}"] = flatten(value[PARAMETERS])
        else:  # a namespace (global_costmap: global_costmap: ros__parameters)
            out.update(node_sections(value, f"{namespace}/{key}"))
    return out


def load(path: Path) -> dict[str, Any]:
    return yaml.safe_load(path.read_text(encoding="utf-8"))
