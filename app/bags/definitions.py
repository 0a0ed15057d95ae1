"""Message definitions and RIHS01 type hashes, as rosbag2 stores them per topic.

A bag carries each type's full definition (nested types appended) so that
any reader can decode it without the package installed. rosbags knows every
Jazzy core type; our own interface packages (tutorial_interfaces, turtlesim)
are read from their installed ``share/<pkg>/msg/*.msg`` files. A service's
request and response (``service_definitions``), as the Foxglove bridge
advertises them, come from its installed ``.srv`` file.
"""

from __future__ import annotations

import os
import re
import sys
import threading
from pathlib import Path

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from app.bags.errors import BagError

_lock = threading.Lock()
_store: Typestore | None = None
# Nested types are registered one at a time; a chain deeper than this is a loop.
MAX_NESTING = 32


def typestore() -> Typestore:
    """Jazzy's types plus whatever installed package types were asked for (shared, locked)."""
    global _store
    with _lock:
        if _store is None:
            _store = get_typestore(Stores.ROS2_JAZZY)
        return _store


def _prefixes() -> list[Path]:
    found = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return [*found, Path(sys.prefix)]


def _msg_file(msgtype: str) -> Path | None:
    pkg, _, name = msgtype.partition("/msg/")
    for prefix in _prefixes():
        path = prefix / "share" / pkg / "msg" / f"{name}.msg"
        if path.is_file():
            return path
    return None


def _register(store: Typestore, msgtype: str) -> None:
    """Add ``msgtype`` (and the nested types it needs) from installed .msg files."""
    pending = [msgtype]
    for _ in range(MAX_NESTING):
        if not pending:
            return
        name = pending[-1]
        path = _msg_file(name)
        if path is None:
            raise BagError(f"no definition of {name} is installed here (see `ros2 interface list`)")
        types = get_types_from_msg(path.read_text(encoding="utf-8"), name)
        missing = [
            sub
            for _fields in types.values()
            for _field_name, field in _fields[1]
            for sub in _nested_names(field)
            if sub not in store.fielddefs and sub not in pending
        ]
        if missing:
            pending.extend(missing)
            continue
        store.register(types)
        pending.pop()
    raise BagError(f"the definition of {msgtype} nests too deeply")


def _nested_names(field: object) -> list[str]:
    """Type names inside one parsed field description (rosbags' nested tuples)."""
    names: list[str] = []
    stack = [field]
    while stack:
        item = stack.pop()
        if isinstance(item, tuple):
            stack.extend(item)
        elif isinstance(item, str) and "/msg/" in item:
            names.append(item)
    return names


def definition(msgtype: str) -> tuple[str, str]:
    """(message definition text, RIHS01 hash) for 'pkg/msg/Name'; BagError if unknown."""
    if "/msg/" not in msgtype:
        raise BagError(f"cannot record {msgtype}: only message types (pkg/msg/Name) go in a bag")
    store = typestore()
    with _lock:
        if msgtype not in store.fielddefs:
            _register(store, msgtype)
        msgdef, _ = store.generate_msgdef(msgtype, ros_version=2)
        return msgdef, store.hash_rihs01(msgtype)


SEPARATOR = "=" * 80  # between a ros2msg definition and each nested type's
_PRIMITIVES = frozenset(
    "bool byte char float32 float64 int8 uint8 int16 uint16 int32 uint32 int64 uint64 "
    "string wstring".split()
)
_FIELD_TYPE = re.compile(r"^([A-Za-z][A-Za-z0-9_]*)(?:/(?:msg/)?([A-Za-z][A-Za-z0-9_]*))?")


def service_definitions(srvtype: str) -> tuple[str, str]:
    """ros2msg texts of 'pkg/srv/Name''s request and response, nested types appended.

    Read from the installed ``share/<pkg>/srv/<Name>.srv`` (BagError if none),
    with comments dropped as rosbag2 drops them.
    """
    pkg, _, name = srvtype.partition("/srv/")
    if not pkg or not name or "/" in name:
        raise BagError(f"{srvtype} is not a service type (pkg/srv/Name)")
    path = next(
        (
            found
            for prefix in _prefixes()
            if (found := prefix / "share" / pkg / "srv" / f"{name}.srv").is_file()
        ),
        None,
    )
    if path is None:
        raise BagError(f"no definition of {srvtype} is installed here")
    halves = re.split(r"^---[ \t]*$", path.read_text(encoding="utf-8"), flags=re.MULTILINE)
    if len(halves) != 2:
        raise BagError(f"{srvtype}: its .srv file is not a request and a response")
    request, response = (_with_nested(half, pkg) for half in halves)
    return request, response


def _with_nested(text: str, pkg: str) -> str:
    lines: list[str] = []
    nested: list[str] = []
    for raw in text.splitlines():
        line = raw.strip()
        if "=" not in line:  # a constant's string value may hold a '#'
            line = line.split("#", 1)[0].strip()
        if not line or line.startswith("#"):
            continue
        found = _FIELD_TYPE.match(line)
        if found is not None and found[2]:
            nested.append(f"{found[1]}/msg/{found[2]}")
        elif found is not None and found[1] not in _PRIMITIVES:
            # A type of the service's own package: named in full, as the nested ones are.
            nested.append(f"{pkg}/msg/{found[1]}")
            line = f"{pkg}/{line}"
        lines.append(line)
    blocks: dict[str, str] = {}
    for msgtype in nested:
        full, _digest = definition(msgtype)
        own, *rest = full.split(f"{SEPARATOR}\n")
        blocks.setdefault(msgtype.replace("/msg/", "/"), own)
        for block in rest:
            header, _, body = block.partition("\n")
            blocks.setdefault(header.removeprefix("MSG: "), body)
    out = "\n".join(lines) + "\n"
    for name, body in blocks.items():
        out += f"{SEPARATOR}\nMSG: {name}\n{body}"
    return out
