"""Any installed ROS message, service or action type <-> plain dicts and YAML.

rosidl_runtime_py is not on PyPI, so this is our own: types are imported by
name with importlib, and the generated classes describe themselves through
``get_fields_and_field_types()`` and ``SLOT_TYPES`` (rosidl_parser types),
which is enough to walk nested messages, arrays and sequences generically.
Every failure is a ``ConversionError`` whose text is one line for a learner.
"""

from __future__ import annotations

import array
import importlib
import math
import re
import time
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar, NoReturn, Protocol, TypeGuard, TypeVar, cast

import yaml
from rosidl_parser import definition as idl

from app.jsonish import JSON
from app.ros.errors import Ros2Error

KINDS = ("msg", "srv", "action")
# A generated message, service or action class: its attributes (Request,
# Goal, SLOT_TYPES, get_fields_and_field_types) are made by rosidl at build
# time, so the type checker cannot know them.
RosType = Any
M = TypeVar("M")  # the message a generated class makes (untyped, as the class is)


class RosMessage(Protocol):
    """A generated message: its class names its fields, their ROS types and rosidl types."""

    SLOT_TYPES: ClassVar[tuple[idl.AbstractType, ...]]

    @classmethod
    def get_fields_and_field_types(cls) -> dict[str, str]: ...


_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")

_INT_RANGES = {
    "int8": (-(2**7), 2**7 - 1),
    "uint8": (0, 2**8 - 1),
    "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
    "short": (-(2**15), 2**15 - 1),
    "unsigned short": (0, 2**16 - 1),
    "long": (-(2**31), 2**31 - 1),
    "unsigned long": (0, 2**32 - 1),
    "long long": (-(2**63), 2**63 - 1),
    "unsigned long long": (0, 2**64 - 1),
}
_FLOATS = {"float": 3.4028234663852886e38, "double": None, "long double": None}


class ConversionError(Ros2Error):
    """Unknown type, unknown field, wrong value type or malformed YAML."""


# ----------------------------------------------------------------- type lookup


def type_name(cls: RosType) -> str:
    """'std_msgs/msg/String' for the class std_msgs.msg.String."""
    module = cls.__module__.split(".")
    return f"{module[0]}/{module[1]}/{cls.__name__}"


def import_type(name: str, kind: str | None = None) -> RosType:
    """Import 'pkg/msg/Name' or 'pkg/Name' (msg, then srv, then action)."""
    if not isinstance(name, str) or not name.strip():
        raise ConversionError("empty type name (expected e.g. std_msgs/msg/String)")
    parts = name.strip().strip("/").split("/")
    if len(parts) == 2:
        pkg, cls_name = parts
        kinds = (kind,) if kind else KINDS
    elif len(parts) == 3:
        pkg, sub, cls_name = parts
        if sub not in KINDS:
            raise ConversionError(
                f"unknown type '{name}': the middle part must be msg, srv or action"
            )
        if kind and sub != kind:
            raise ConversionError(f"'{name}' is not a {_KIND_WORD[kind]} type")
        kinds = (sub,)
    else:
        raise ConversionError(f"malformed type name '{name}' (expected pkg/msg/Name or pkg/Name)")
    if not (_NAME.match(pkg) and _NAME.match(cls_name)):
        raise ConversionError(f"malformed type name '{name}' (expected pkg/msg/Name or pkg/Name)")
    for sub in kinds:
        try:
            module = importlib.import_module(f"{pkg}.{sub}")
        except ImportError:
            continue
        cls = getattr(module, cls_name, None)
        if isinstance(cls, type) and _looks_generated(cls, sub):
            return cls
    wanted = _KIND_WORD[kinds[0]] if len(kinds) == 1 else "message, service or action"
    raise ConversionError(f"unknown {wanted} type '{name}' (see `ros2 interface list`)")


_KIND_WORD = {"msg": "message", "srv": "service", "action": "action"}


def _looks_generated(cls: type, kind: str) -> bool:
    if kind == "msg":
        return hasattr(cls, "get_fields_and_field_types")
    if kind == "srv":
        return hasattr(cls, "Request") and hasattr(cls, "Response")
    return hasattr(cls, "Goal") and hasattr(cls, "Result") and hasattr(cls, "Feedback")


def is_message(value: object) -> TypeGuard[RosMessage]:
    return hasattr(type(value), "get_fields_and_field_types") and hasattr(value, "__slots__")


def _nested_class(slot: idl.NamespacedType) -> RosType:
    return import_type("/".join([*slot.namespaces, slot.name]))


def fields_of(cls: RosType) -> list[tuple[str, str, idl.AbstractType]]:
    """(name, ros type text, rosidl slot type) for every field of a message class."""
    names = list(cls.get_fields_and_field_types().items())
    return [(n, t, slot) for (n, t), slot in zip(names, cls.SLOT_TYPES, strict=True)]


# ------------------------------------------------------------ message -> dict


def to_plain(value: object, *, max_items: int | None = None) -> JSON:
    """A message (or any field value) as plain Python: dicts, lists, numbers, text."""
    if is_message(value):
        return {
            name: to_plain(getattr(value, name), max_items=max_items)
            for name in type(value).get_fields_and_field_types()
        }
    if isinstance(value, bytes | bytearray):
        return value[0] if len(value) == 1 and isinstance(value, bytes) else list(value)
    if hasattr(value, "tolist"):  # numpy arrays and numpy scalars
        value = value.tolist()
    if isinstance(value, array.array):
        value = value.tolist()
    if isinstance(value, list | tuple):
        items = [to_plain(v, max_items=max_items) for v in value[: max_items or None]]
        if max_items is not None and len(value) > max_items:
            items.append(f"... ({len(value) - max_items} more)")
        return items
    return cast(JSON, value)  # what is left of a message field: a number, text, a bool


def to_yaml(msg: object, *, max_items: int | None = 32) -> str:
    """A message as YAML (lists of numbers inline, to stay short), without the --- line."""
    plain = to_plain(msg, max_items=max_items)
    if not plain:
        return "{}"
    return dump_yaml(plain)


class _Dumper(yaml.SafeDumper):  # type: ignore[misc]  # PyYAML ships no types
    """Block-style mappings (as ros2 prints them), lists of plain values on one line."""


def _represent_list(dumper: yaml.SafeDumper, data: list[object]) -> yaml.SequenceNode:
    flat = all(not isinstance(v, dict | list) for v in data)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flat)


_Dumper.add_representer(list, _represent_list)


def dump_yaml(value: object) -> str:
    text = yaml.dump(value, Dumper=_Dumper, sort_keys=False, default_flow_style=False, width=100)
    return str(text).rstrip()


def field_value(msg: object, path: str) -> object:
    """The value at 'a.b.c' (or 'a.b[2]'), as `ros2 topic echo --field` selects it."""
    current = msg
    for part in [p for p in path.strip().split(".") if p]:
        match = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)", part)
        if not match:
            raise ConversionError(f"malformed field path '{path}'")
        name, indexes = match.groups()
        if not is_message(current) or name not in type(current).get_fields_and_field_types():
            raise ConversionError(f"no field '{name}' in {_describe_msg(current)} (path '{path}')")
        current = getattr(current, name)
        for index in re.findall(r"\[(\d+)\]", indexes):
            try:
                current = cast("Sequence[object]", current)[int(index)]
            except (IndexError, TypeError):
                raise ConversionError(f"index {index} out of range in '{path}'") from None
    return current


def _describe_msg(value: object) -> str:
    return type_name(type(value)) if is_message(value) else f"a {type(value).__name__}"


# ------------------------------------------------------------ dict -> message


def parse_yaml(text: str | None) -> dict[str, object]:
    """YAML (or JSON) text from a learner -> a mapping; empty text is {}."""
    if text is None or not text.strip():
        return {}
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise ConversionError(f"malformed YAML: {problem}{where}") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConversionError(
            f"the YAML must be a mapping like '{{field: value}}', got {_kind_of(data)}"
        )
    return data


def from_yaml(cls: type[M], text: str | None) -> M:
    return fill(cls, parse_yaml(text))


def fill(cls: type[M], data: Mapping[str, object] | None, path: str = "") -> M:
    """A new ``cls`` message with the fields named in ``data`` set (others default)."""
    msg = cls()
    if data is None:
        return msg
    if not isinstance(data, dict):
        raise ConversionError(
            f"{_at(path)}expected a mapping for {type_name(cls)}, got {_kind_of(data)}"
        )
    fields = {name: (ros_type, slot) for name, ros_type, slot in fields_of(cls)}
    for key, value in data.items():
        if key not in fields:
            known = ", ".join(fields) or "none"
            raise ConversionError(
                f"unknown field '{_join(path, str(key))}' in {type_name(cls)} (fields: {known})"
            )
        ros_type, slot = fields[key]
        field_path = _join(path, key)
        coerced = _coerce(slot, ros_type, value, field_path)
        try:
            setattr(msg, key, coerced)
        except (AssertionError, TypeError, ValueError, OverflowError) as exc:
            detail = str(exc).splitlines()[0] if str(exc) else "rejected by the message class"
            raise ConversionError(f"field '{field_path}' ({ros_type}): {detail}") from None
    return msg


def _join(path: str, key: str) -> str:
    return f"{path}.{key}" if path else key


def _at(path: str) -> str:
    return f"field '{path}': " if path else ""


def _kind_of(value: object) -> str:
    if isinstance(value, bool):
        return f"a boolean ({value})"
    if isinstance(value, int):
        return f"an integer ({value})"
    if isinstance(value, float):
        return f"a number ({value})"
    if isinstance(value, str):
        shown = value if len(value) <= 30 else value[:27] + "..."
        return f"text ('{shown}')"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a mapping"
    if value is None:
        return "nothing (null)"
    return f"a {type(value).__name__}"


def _wrong(path: str, ros_type: str, value: object, expected: str) -> ConversionError:
    return ConversionError(f"field '{path}' ({ros_type}) expects {expected}, got {_kind_of(value)}")


def _coerce(slot: idl.AbstractType, ros_type: str, value: object, path: str) -> object:
    if isinstance(slot, idl.NamespacedType):
        cls = _nested_class(slot)
        if type_name(cls) == "builtin_interfaces/msg/Time" and value == "now":
            now = time.time_ns()
            return cls(sec=now // 10**9, nanosec=now % 10**9)
        if isinstance(value, cls):
            return value
        if not isinstance(value, dict):
            raise _wrong(path, ros_type, value, f"a mapping of {type_name(cls)} fields")
        return fill(cls, value, path)
    if isinstance(slot, idl.AbstractNestedType):
        if isinstance(value, str) and _is_byte_like(slot.value_type):
            value = list(value.encode())
        if not isinstance(value, list | tuple):
            raise _wrong(path, ros_type, value, "a list")
        if isinstance(slot, idl.Array) and len(value) != slot.size:
            raise ConversionError(
                f"field '{path}' ({ros_type}) needs exactly {slot.size} items, got {len(value)}"
            )
        if isinstance(slot, idl.BoundedSequence) and len(value) > slot.maximum_size:
            raise ConversionError(
                f"field '{path}' ({ros_type}) takes at most {slot.maximum_size} items, "
                f"got {len(value)}"
            )
        return [
            _coerce(slot.value_type, ros_type, item, f"{path}[{i}]") for i, item in enumerate(value)
        ]
    if isinstance(slot, idl.AbstractGenericString):
        if isinstance(value, bool | int | float) and not isinstance(value, bool):
            value = str(value)
        if not isinstance(value, str):
            raise _wrong(path, ros_type, value, "text")
        limit = getattr(slot, "maximum_size", None)
        if limit is not None and len(value) > limit:
            raise ConversionError(f"field '{path}' ({ros_type}) takes at most {limit} characters")
        return value
    if isinstance(slot, idl.BasicType):
        return _coerce_basic(slot.typename, ros_type, value, path)
    raise ConversionError(f"field '{path}' has a type this tool cannot fill ({ros_type})")


def _is_byte_like(slot: idl.AbstractType) -> bool:
    return isinstance(slot, idl.BasicType) and slot.typename in ("octet", "uint8", "char")


def _coerce_basic(typename: str, ros_type: str, value: object, path: str) -> object:
    if typename == "boolean":
        if not isinstance(value, bool):
            raise _wrong(path, ros_type, value, "true or false")
        return value
    if typename in _INT_RANGES:
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        if isinstance(value, bool) or not isinstance(value, int):
            raise _wrong(path, ros_type, value, "an integer")
        low, high = _INT_RANGES[typename]
        if not low <= value <= high:
            raise ConversionError(
                f"field '{path}' ({ros_type}) must be between {low} and {high}, got {value}"
            )
        return value
    if typename in _FLOATS:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise _wrong(path, ros_type, value, "a number")
        value = float(value)
        limit = _FLOATS[typename]
        if limit is not None and math.isfinite(value) and abs(value) > limit:
            raise ConversionError(f"field '{path}' ({ros_type}) is out of range for float32")
        return value
    if typename == "octet":
        if isinstance(value, bytes) and len(value) == 1:
            return value
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 255:
            raise _wrong(path, ros_type, value, "a byte (0-255)")
        return bytes([value])
    if typename in ("char", "wchar"):
        if isinstance(value, str) and len(value) == 1:
            return value
        if typename == "char" and isinstance(value, int) and not isinstance(value, bool):
            return (
                chr(value)
                if 0 <= value <= 255
                else _raise(_wrong(path, ros_type, value, "a character"))
            )
        raise _wrong(path, ros_type, value, "a single character")
    raise ConversionError(f"field '{path}' has a type this tool cannot fill ({ros_type})")


def _raise(exc: Exception) -> NoReturn:
    raise exc


# ------------------------------------------------------------ form support


def leaf_fields(cls: type, prefix: str = "", depth: int = 0) -> list[tuple[str, str, str]]:
    """Flattened (path, ros type, widget kind) of a message, for generated forms.

    Widget kinds: 'bool', 'int', 'float', 'text', 'yaml' (lists and anything
    deeper than a few levels are typed as YAML).
    """
    out: list[tuple[str, str, str]] = []
    for name, ros_type, slot in fields_of(cls):
        path = _join(prefix, name)
        if isinstance(slot, idl.NamespacedType) and depth < 3:
            out += leaf_fields(_nested_class(slot), path, depth + 1)
        elif isinstance(slot, idl.BasicType):
            if slot.typename == "boolean":
                out.append((path, ros_type, "bool"))
            elif slot.typename in _INT_RANGES or slot.typename == "octet":
                out.append((path, ros_type, "int"))
            elif slot.typename in _FLOATS:
                out.append((path, ros_type, "float"))
            else:
                out.append((path, ros_type, "text"))
        elif isinstance(slot, idl.AbstractGenericString):
            out.append((path, ros_type, "text"))
        else:
            out.append((path, ros_type, "yaml"))
    return out


def value_from_text(kind: str, text: str) -> object:
    """Interpret what a learner typed into one generated form field."""
    if kind == "text":
        return text
    if kind == "yaml":
        if not text.strip():
            return None
        try:
            return yaml.safe_load(text)
        except yaml.YAMLError:
            raise ConversionError(f"malformed YAML: {text[:40]!r}") from None
    if kind == "bool":
        lowered = text.strip().lower()
        if lowered in ("true", "1", "yes", "on"):
            return True
        if lowered in ("false", "0", "no", "off", ""):
            return False
        raise ConversionError(f"expected true or false, got {text[:40]!r}")
    if kind == "int":
        try:
            return int(text.strip() or "0", 0)
        except ValueError:
            raise ConversionError(f"expected an integer, got {text[:40]!r}") from None
    if kind == "float":
        try:
            return float(text.strip() or "0")
        except ValueError:
            raise ConversionError(f"expected a number, got {text[:40]!r}") from None
    raise ConversionError(f"unknown form field kind {kind!r}")


def nest(flat: Mapping[str, object]) -> dict[str, object]:
    """{'linear.x': 1} -> {'linear': {'x': 1}}; None values are left out."""
    out: dict[str, object] = {}
    for path, value in flat.items():
        if value is None:
            continue
        parts = path.split(".")
        target = out
        for part in parts[:-1]:
            target = cast("dict[str, object]", target.setdefault(part, {}))
        target[parts[-1]] = value
    return out


def fill_from_form(cls: type[M], values: Mapping[str, object]) -> M:
    """A message from generated form values (already typed or raw text)."""
    kinds = {path: kind for path, _t, kind in leaf_fields(cls)}
    typed: dict[str, object] = {}
    for path, value in values.items():
        if path not in kinds:
            raise ConversionError(f"unknown field '{path}' in {type_name(cls)}")
        if isinstance(value, str) and kinds[path] != "text":
            try:
                value = value_from_text(kinds[path], value)
            except ConversionError as exc:
                raise ConversionError(f"field '{path}': {exc}") from None
        typed[path] = value
    return fill(cls, nest(typed))


def message_repr(msg: object) -> str:
    """ros2cli's one-line form: 'std_msgs.msg.String(data=...)'."""
    return repr(msg)


def yaml_inline(msg: object) -> str:
    """A message as '{a: 1, b: 2}', quoted for the equivalent ros2 command line."""
    text = str(yaml.safe_dump(to_plain(msg), default_flow_style=True, width=10_000)).strip()
    return "'" + text.replace("'", "'\"'\"'") + "'"
