"""Message definitions and RIHS01 type hashes, as rosbag2 stores them per topic.

A bag carries each type's full definition (nested types appended) so that
any reader can decode it without the package installed. rosbags knows every
Jazzy core type; our own interface packages (tutorial_interfaces, turtlesim)
are read from their installed ``share/<pkg>/msg/*.msg`` files.
"""

from __future__ import annotations

import os
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
