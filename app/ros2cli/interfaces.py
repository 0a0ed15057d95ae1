"""`ros2 interface list/show/packages`: read the ament index, no DDS needed.

Interface packages register themselves under the ament resource type
``rosidl_interfaces``; their definitions live in ``share/<pkg>/{msg,srv,action}``.
The ROS wheels install into the venv prefix, so that prefix is the default
search path when ``AMENT_PREFIX_PATH`` is not set.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from collections.abc import Sequence
from pathlib import Path

from app.ros.context import CallContext
from app.ros.convert import import_type
from app.ros.errors import Ros2Error
from app.ros2cli.common import Commands, Ros2cliMessage, Verb
from app.ros2cli.msg_yaml import message_to_yaml

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


def show(
    type_text: str, *, expand: bool = True, comments: bool = True, nested_comments: bool = False
) -> str:
    """The definition text, nested message types expanded (one tab deeper) as ros2 does.

    As `ros2 interface show`: the top level keeps its comments and empty lines
    unless ``comments`` is False (``--no-comments``); nested definitions show
    theirs only with ``nested_comments`` (``--all-comments``). Without them a
    line loses its trailing comment, and empty or comment lines are left out.
    """
    path, package = _show_path(type_text)
    lines = path.read_text().rstrip("\n").splitlines()
    return "\n".join(_expand(lines, package, expand, 0, comments, nested_comments))


def _show_path(type_text: str) -> tuple[Path, str]:
    """The file `ros2 interface show` reads (pkg/kind/Name only), or ros2cli's words."""
    ensure_ament_prefix()
    from ament_index_python import PackageNotFoundError, get_package_prefix

    parts = type_text.split("/")
    if len(parts) != 3:
        raise Ros2cliMessage(f"Invalid name '{type_text}'. Expected three parts separated by '/'")
    try:
        prefix = get_package_prefix(parts[0])
    except (PackageNotFoundError, ValueError):
        raise Ros2cliMessage(f"Unknown package '{parts[0]}'") from None
    base = os.path.join(prefix, "share", type_text)
    for path in (f"{base}.{parts[1]}", f"{base}.idl"):
        if parts[1] in _EXT and path.endswith(_EXT[parts[1]]) and os.path.isfile(path):
            return Path(path), parts[0]
    raise Ros2cliMessage(f"Could not find the interface '{base}.idl'")


def _without_comment(line: str, keep: bool) -> str | None:
    """The line as printed: None when it is left out (empty or a comment, comments hidden)."""
    if keep:
        return line
    stripped = line.strip()
    if not stripped or stripped.startswith("#"):
        return None
    if "#" in line:
        return line[: line.index("#")].strip()
    return line


def _expand(
    lines: list[str], package: str, expand: bool, depth: int, comments: bool, nested: bool
) -> list[str]:
    out: list[str] = []
    indent = "\t" * depth
    for raw in lines:
        line = _without_comment(raw.rstrip(), comments)
        if line is None:
            continue
        out.append(indent + line if line else "")
        match = _FIELD.match(raw)
        if not expand or not match or depth >= 8 or "=" in raw.split("#", 1)[0]:
            continue
        base = match.group(1)
        if base in _PRIMITIVES or base.startswith("string<") or base.startswith("---"):
            continue
        nested_type = _nested_name(base, package)
        try:
            nested_path = definition_path(nested_type)[0]
        except Ros2Error:
            continue
        nested_pkg = nested_type.split("/")[0]
        nested_lines = nested_path.read_text().rstrip("\n").splitlines()
        out += _expand(nested_lines, nested_pkg, expand, depth + 1, nested, nested)
    return out


def _nested_name(base: str, package: str) -> str:
    if base == "Header":
        return "std_msgs/msg/Header"
    if "/" not in base:
        return f"{package}/msg/{base}"
    pkg, name = base.split("/", 1)
    return f"{pkg}/msg/{name.split('/')[-1]}"


def prototype(type_text: str, quotes: bool = True) -> str:
    """`ros2 interface proto`: a default instance as YAML (a goal or request for actions
    and services), in double quotes unless ``quotes`` is False."""
    cls = import_type(type_text)
    if hasattr(cls, "Goal"):
        cls = cls.Goal
    elif hasattr(cls, "Request"):
        cls = cls.Request
    text = message_to_yaml(cls())
    return f'"{text}"' if quotes else text


# --- `ros2 interface ...`: arguments as ros2cli takes them, and what each verb does


def add_verbs(v: Commands, verb: Verb) -> None:
    """`ros2 interface list/packages/package/show/proto`, with ros2cli's arguments."""
    p = verb(v, "list", "List all interface types available", _interface_list)
    only_kinds(p)
    packages_help = "Output a list of packages that provide interfaces"
    p = verb(v, "packages", packages_help, _interface_packages)
    only_kinds(
        p,
        (
            "Only list packages that generate messages",
            "Only list packages that generate services",
            "Only list packages that generate actions",
        ),
    )
    p = verb(
        v,
        "package",
        "Output a list of available interface types within one package",
        _interface_package,
    )
    only_kinds(p)
    p.add_argument("package_name", help="Name of the ROS package (e.g. 'example_interfaces')")
    p = verb(v, "show", "Output the interface definition", _interface_show)
    comment_options(p)
    p.add_argument(
        "type",
        help="Show an interface definition (e.g. 'example_interfaces/msg/String'). Passing '-' "
        "reads the argument from stdin (e.g. 'ros2 topic type /chatter | ros2 interface show -').",
    )
    p.epilog = "Not supported here: '-' (reading the type from standard input)."
    p = verb(v, "proto", "Output an interface prototype", _interface_proto)
    p.add_argument(
        "type", help="Show an interface definition (e.g. 'example_interfaces/msg/String')"
    )
    p.add_argument("--no-quotes", action="store_true", help="if true output has no outer quotes.")


def only_kinds(p: argparse.ArgumentParser, what: Sequence[str] | None = None) -> None:
    """`ros2 interface list/package(s)`: -m, -s, -a, with each verb's own help texts."""
    texts = what or (
        "Print out only the message types",
        "Print out only the service types",
        "Print out only the action types",
    )
    for short, long, text in zip(
        ("-m", "-s", "-a"), ("--only-msgs", "--only-srvs", "--only-actions"), texts, strict=True
    ):
        p.add_argument(short, long, action="store_true", help=text)


def comment_options(p: argparse.ArgumentParser) -> None:
    """`ros2 interface show`: --all-comments or --no-comments."""
    group = p.add_mutually_exclusive_group()
    group.add_argument(
        "--all-comments",
        action="store_true",
        help="Show all comments, including for nested interface definitions",
    )
    group.add_argument("--no-comments", action="store_true", help="Show no comments or whitespace")


def _interface_list(ctx: CallContext, args: argparse.Namespace) -> int:
    found = all_interfaces()
    chosen = [
        k
        for k, flag in (
            ("msg", args.only_msgs),
            ("srv", args.only_srvs),
            ("action", args.only_actions),
        )
        if flag
    ] or ["msg", "srv", "action"]
    titles = {"msg": "Messages", "srv": "Services", "action": "Actions"}
    for kind in chosen:
        ctx.write(f"{titles[kind]}:")
        for name in found[kind]:
            ctx.write(f"    {name}")
    return 0


def _kinds(args: argparse.Namespace) -> set[str]:
    """-m/-s/-a: which kinds to list (none given: all)."""
    chosen = {
        k
        for k, on in (
            ("msg", args.only_msgs),
            ("srv", args.only_srvs),
            ("action", args.only_actions),
        )
        if on
    }
    return chosen or {"msg", "srv", "action"}


def _interface_packages(ctx: CallContext, args: argparse.Namespace) -> int:
    kinds = _kinds(args)
    for package, names in interface_packages().items():
        if any(name.split("/", 1)[0] in kinds for name in names):
            ctx.write(package)
    return 0


def _interface_package(ctx: CallContext, args: argparse.Namespace) -> int:
    packages = interface_packages()
    if args.package_name not in packages:
        raise Ros2cliMessage(f"Unknown package '{args.package_name}'")
    kinds = _kinds(args)
    for name in packages[args.package_name]:
        if name.split("/", 1)[0] in kinds:
            ctx.write(f"{args.package_name}/{name}")
    return 0


def _interface_proto(ctx: CallContext, args: argparse.Namespace) -> int:
    for line in prototype(args.type, quotes=not args.no_quotes).split("\n"):
        ctx.write(line)
    return 0


def _interface_show(ctx: CallContext, args: argparse.Namespace) -> int:
    text = show(
        args.type,
        expand=True,
        comments=not args.no_comments,
        nested_comments=args.all_comments,
    )
    for line in text.split("\n"):
        ctx.write(line)
    return 0
