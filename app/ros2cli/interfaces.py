"""`ros2 interface list/show/packages`: read the ament index, no DDS needed.

Interface packages register themselves under the ament resource type
``rosidl_interfaces``; their definitions live in ``share/<pkg>/{msg,srv,action}``.
The ROS wheels install into the venv prefix, so that prefix is the default
search path when ``AMENT_PREFIX_PATH`` is not set.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

from app.ros.errors import Ros2Error

_EXT = {"msg": ".msg", "srv": ".srv", "action": ".action"}


def ensure_ament_prefix() -> None:
    """ament_index_python refuses to work without AMENT_PREFIX_PATH; default to the venv."""
    if not os.environ.get("AMENT_PREFIX_PATH"):
        os.environ["AMENT_PREFIX_PATH"] = sys.prefix


def interface_packages() -> dict[str, list[str]]:
    """{package: ['msg/Name', 'srv/Name', ...]} for every installed interface package."""
    ensure_ament_prefix()
    from ament_index_python import get_resource, get_resources

    out: dict[str, list[str]] = {}
    for package in sorted(get_resources("rosidl_interfaces")):
        content, _prefix = get_resource("rosidl_interfaces", package)
        names = set()
        for line in content.splitlines():
            kind, _, file_name = line.strip().partition("/")
            stem, ext = os.path.splitext(file_name)
            if kind in _EXT and ext in (".msg", ".srv", ".action", ".idl") and stem:
                names.add(f"{kind}/{stem}")
        out[package] = sorted(names)
    return out


def all_interfaces() -> dict[str, list[str]]:
    """{'msg': ['pkg/msg/Name', ...], 'srv': [...], 'action': [...]}."""
    out: dict[str, list[str]] = {"msg": [], "srv": [], "action": []}
    for package, names in interface_packages().items():
        for name in names:
            kind = name.split("/", 1)[0]
            out[kind].append(f"{package}/{name}")
    return out


def definition_path(type_text: str) -> tuple[Path, str, str, str]:
    """(file, package, kind, Name) of an interface given as pkg/kind/Name or pkg/Name."""
    ensure_ament_prefix()
    from ament_index_python import PackageNotFoundError, get_package_share_directory

    parts = type_text.strip().strip("/").split("/")
    if len(parts) not in (2, 3) or not all(parts):
        raise Ros2Error(f"malformed type name '{type_text}' (expected pkg/msg/Name or pkg/Name)")
    package, name = parts[0], parts[-1]
    kinds = [parts[1]] if len(parts) == 3 else list(_EXT)
    try:
        share = Path(get_package_share_directory(package))
    except (PackageNotFoundError, ValueError):
        raise Ros2Error(f"unknown package '{package}' (see `ros2 interface packages`)") from None
    for kind in kinds:
        path = share / kind / f"{name}{_EXT.get(kind, '.msg')}"
        if kind in _EXT and path.is_file():
            return path, package, kind, name
    raise Ros2Error(f"unknown interface type '{type_text}' (see `ros2 interface list`)")


_FIELD = re.compile(r"^\s*([A-Za-z][A-Za-z0-9_]*(?:/[A-Za-z0-9_]+)*)(\[[^\]]*\])?\s+\w")
_PRIMITIVES = {
    "bool",
    "byte",
    "char",
    "float32",
    "float64",
    "int8",
    "uint8",
    "int16",
    "uint16",
    "int32",
    "uint32",
    "int64",
    "uint64",
    "string",
    "wstring",
}


def show(type_text: str, *, expand: bool = True) -> str:
    """The definition text, with nested message types expanded (indented) as ros2 does."""
    path, package, _kind, _name = definition_path(type_text)
    return "\n".join(_expand(path.read_text().rstrip("\n").splitlines(), package, expand, 0))


def _expand(lines: list[str], package: str, expand: bool, depth: int) -> list[str]:
    out: list[str] = []
    indent = "\t" * depth
    for line in lines:
        if depth and (not line.strip() or line.lstrip().startswith("#")):
            continue  # nested definitions are shown without their comments
        out.append(indent + line)
        match = _FIELD.match(line)
        if not expand or not match or depth >= 4 or "=" in line.split("#", 1)[0]:
            continue
        base = match.group(1)
        if base in _PRIMITIVES or base.startswith("string<") or base.startswith("---"):
            continue
        nested = _nested_name(base, package)
        try:
            nested_path = definition_path(nested)[0]
        except Ros2Error:
            continue
        nested_pkg = nested.split("/")[0]
        out += _expand(nested_path.read_text().splitlines(), nested_pkg, expand, depth + 1)
    return out


def _nested_name(base: str, package: str) -> str:
    if base == "Header":
        return "std_msgs/msg/Header"
    if "/" not in base:
        return f"{package}/msg/{base}"
    pkg, name = base.split("/", 1)
    return f"{pkg}/msg/{name.split('/')[-1]}"
