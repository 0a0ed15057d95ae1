"""Messages as ros2cli prints them: block-style YAML, fields in definition order.

`ros2 topic echo`, `ros2 action send_goal` and friends print a message through
rosidl_runtime_py's ``message_to_yaml`` (not on PyPI). What it shows is plain
PyYAML output of an ordered mapping: block style, lists as ``- item`` lines
(not indented under their key), no line wrapping, unicode kept, and sequences
longer than a limit cut with a ``'...'`` item. This module gives the same text
from our own walk over the message.
"""

from __future__ import annotations

import array
import sys
from typing import Any

import yaml

from app.ros.convert import is_message

# `ros2 topic echo` cuts arrays, bytes and strings after this many items.
ECHO_TRUNCATE_LENGTH = 128


class _BlockDumper(yaml.SafeDumper):
    """PyYAML's defaults, with mappings kept in insertion (field) order."""


def _represent_dict(dumper: yaml.SafeDumper, data: dict) -> yaml.MappingNode:
    return dumper.represent_mapping("tag:yaml.org,2002:map", data.items())


_BlockDumper.add_representer(dict, _represent_dict)


def _cut(text: str, limit: int | None) -> str:
    return text[:limit] + "..." if limit is not None and len(text) > limit else text


def plain_value(value: Any, limit: int | None = None) -> Any:
    """One field value as ros2cli turns it into YAML data (bytes become text, arrays lists)."""
    if isinstance(value, bytes | bytearray):
        return _cut("".join(chr(b) for b in value), limit)
    if isinstance(value, str):
        return _cut(value, limit)
    if hasattr(value, "tolist") and not isinstance(value, bool | int | float):
        value = value.tolist()  # numpy arrays and numpy scalars
    if isinstance(value, array.array):
        value = value.tolist()
    if isinstance(value, list | tuple):
        items = [plain_value(v, limit) for v in value[: limit if limit is not None else None]]
        if limit is not None and len(value) > limit:
            items.append("...")
        return items
    if is_message(value):
        return message_to_plain(value, limit)
    return value


def message_to_plain(msg: Any, limit: int | None = None) -> dict[str, Any]:
    """A message as an ordered dict of plain values, in the order its definition gives."""
    return {
        name: plain_value(getattr(msg, name), limit) for name in msg.get_fields_and_field_types()
    }


def message_to_yaml(msg: Any, truncate_length: int | None = None) -> str:
    """Block-style YAML text of a message, ending in a newline (``{}`` for an empty one)."""
    return yaml.dump(
        message_to_plain(msg, truncate_length),
        Dumper=_BlockDumper,
        allow_unicode=True,
        width=sys.maxsize,
        default_flow_style=False,
        sort_keys=False,
    )


def printed(text: str) -> list[str]:
    """The lines Python's ``print(text)`` shows (a trailing newline gives an empty line)."""
    return text.split("\n")
