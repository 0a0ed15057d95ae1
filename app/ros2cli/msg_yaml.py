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
from collections.abc import Collection
from typing import cast

import yaml
from rosidl_parser import definition as idl

from app.ros.convert import RosMessage, is_message

# `ros2 topic echo` cuts arrays, bytes and strings after this many items.
ECHO_TRUNCATE_LENGTH = 128

# An array or sequence field: a list, tuple, array.array or numpy array.
_Array = Collection[object]


class _BlockDumper(yaml.SafeDumper):
    """PyYAML's defaults, with mappings kept in insertion (field) order."""


def _represent_dict(dumper: yaml.SafeDumper, data: dict) -> yaml.MappingNode:
    """A mapping node with no style of its own: PyYAML writes it in block style (flow only
    inside a flow list), whatever ``default_flow_style`` says. So `--flow-style` puts only
    the lists in flow style (``[0, 1]``), as ros2cli's message_to_yaml does."""
    pairs = [(dumper.represent_data(k), dumper.represent_data(v)) for k, v in data.items()]
    return yaml.MappingNode("tag:yaml.org,2002:map", pairs)


_BlockDumper.add_representer(dict, _represent_dict)


def _cut(text: str, limit: int | None) -> str:
    return text[:limit] + "..." if limit is not None and len(text) > limit else text


def _type_name(value_type: idl.AbstractType) -> str:
    if isinstance(value_type, idl.BasicType):
        return str(value_type.typename)
    if isinstance(value_type, idl.AbstractWString):
        return "wstring"
    if isinstance(value_type, idl.AbstractString):
        return "string"
    if isinstance(value_type, idl.NamespacedType):
        return "/".join(value_type.namespaced_name())
    if isinstance(value_type, idl.NamedType):
        return str(value_type.name)
    return "unknown"


def array_summary(value: _Array, field_type: idl.AbstractNestedType) -> str:
    """What `--no-arr` prints instead of an array or sequence field."""
    name = _type_name(field_type.value_type)
    if isinstance(field_type, idl.Array):
        return f"<array type: {name}[{field_type.size}]>"
    if isinstance(field_type, idl.BoundedSequence):
        return f"<sequence type: {name}[{field_type.maximum_size}], length: {len(value)}>"
    if isinstance(field_type, idl.UnboundedSequence):
        return f"<sequence type: {name}, length: {len(value)}>"
    return "unknown"


def plain_value(
    value: object,
    limit: int | None = None,
    *,
    field_type: idl.AbstractType | None = None,
    no_arr: bool = False,
    no_str: bool = False,
) -> object:
    """One field value as ros2cli turns it into YAML data (bytes become text, arrays lists)."""
    if isinstance(value, bytes | bytearray):
        return _cut("".join(chr(b) for b in value), limit)
    if isinstance(value, str):
        return f"<string length: <{len(value)}>>" if no_str else _cut(value, limit)
    if isinstance(value, list | tuple | array.array) or (
        hasattr(value, "tolist") and hasattr(value, "shape") and value.shape != ()
    ):
        sequence = cast(_Array, value)
        if no_arr and field_type is not None:
            return array_summary(sequence, field_type)
        items = [
            plain_value(v, limit, no_arr=no_arr, no_str=no_str)
            for v in list(sequence)[: limit if limit is not None else None]
        ]
        if limit is not None and len(sequence) > limit:
            items.append("...")
        return items
    if hasattr(value, "item") and not isinstance(value, bool | int | float):
        return value.item()  # a numpy scalar
    if is_message(value):
        return message_to_plain(value, limit, no_arr=no_arr, no_str=no_str)
    return value


def message_to_plain(
    msg: RosMessage, limit: int | None = None, *, no_arr: bool = False, no_str: bool = False
) -> dict[str, object]:
    """A message as an ordered dict of plain values, in the order its definition gives."""
    return {
        name: plain_value(getattr(msg, name), limit, field_type=slot, no_arr=no_arr, no_str=no_str)
        for name, slot in zip(msg.get_fields_and_field_types(), msg.SLOT_TYPES, strict=False)
    }


def message_to_yaml(
    msg: RosMessage,
    truncate_length: int | None = None,
    *,
    no_arr: bool = False,
    no_str: bool = False,
    flow_style: bool = False,
) -> str:
    """YAML text of a message, ending in a newline (``{}`` for an empty one)."""
    return yaml.dump(
        message_to_plain(msg, truncate_length, no_arr=no_arr, no_str=no_str),
        Dumper=_BlockDumper,
        allow_unicode=True,
        width=sys.maxsize,
        default_flow_style=flow_style,
        sort_keys=False,
    )


def message_to_csv(
    msg: RosMessage,
    truncate_length: int | None = None,
    *,
    no_arr: bool = False,
    no_str: bool = False,
) -> str:
    """`ros2 topic echo --csv`: every leaf value, depth first, joined by commas."""

    def text(value: object, field_type: idl.AbstractType | None = None) -> str:
        if isinstance(value, list | tuple | array.array) or (
            hasattr(value, "tolist") and hasattr(value, "shape") and value.shape != ()
        ):
            sequence = cast(_Array, value)
            if no_arr and field_type is not None:
                return array_summary(sequence, field_type)
            parts = []
            for i, item in enumerate(list(sequence)):
                if truncate_length is not None and i >= truncate_length:
                    parts.append("...")
                    break
                parts.append(text(item))
            return ",".join(parts)
        if is_message(value):
            return message_to_csv(value, truncate_length, no_arr=no_arr, no_str=no_str)
        if isinstance(value, str) and no_str:
            return f"<string length: <{len(value)}>>"
        if truncate_length is not None and isinstance(value, str):
            value = _cut(value, truncate_length)
        elif truncate_length is not None and isinstance(value, bytes):
            if len(value) > truncate_length:
                value = value[:truncate_length] + b"..."
        return str(value)

    result = ""
    for name, slot in zip(msg.get_fields_and_field_types(), msg.SLOT_TYPES, strict=False):
        # A comma only once something was written: an empty first field adds none.
        result += ("," if result else "") + text(getattr(msg, name), slot)
    return result
