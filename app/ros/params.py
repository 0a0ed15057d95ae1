"""Parameters of any node, through its rcl_interfaces services: list, get, describe, set.

Conversion between ``ParameterValue`` and plain Python lives here once; the
`ros2 param` verbs, the Parameters panel and lesson checks all use it.
"""

from __future__ import annotations

import math
from typing import Any, cast

import yaml
from rcl_interfaces.msg import Parameter, ParameterDescriptor, ParameterType, ParameterValue
from rcl_interfaces.srv import (
    DescribeParameters,
    GetParameters,
    ListParameters,
    SetParameters,
)

from app.ros.calls import call_service
from app.ros.context import CallContext
from app.ros.errors import Ros2Error
from app.ros.graph import require_node

TYPE_WORDS = {
    ParameterType.PARAMETER_BOOL: ("Boolean value is", "bool_value"),
    ParameterType.PARAMETER_INTEGER: ("Integer value is", "integer_value"),
    ParameterType.PARAMETER_DOUBLE: ("Double value is", "double_value"),
    ParameterType.PARAMETER_STRING: ("String value is", "string_value"),
    ParameterType.PARAMETER_BYTE_ARRAY: ("Byte values are", "byte_array_value"),
    ParameterType.PARAMETER_BOOL_ARRAY: ("Boolean values are", "bool_array_value"),
    ParameterType.PARAMETER_INTEGER_ARRAY: ("Integer values are", "integer_array_value"),
    ParameterType.PARAMETER_DOUBLE_ARRAY: ("Double values are", "double_array_value"),
    ParameterType.PARAMETER_STRING_ARRAY: ("String values are", "string_array_value"),
}
TYPE_NAMES = {
    ParameterType.PARAMETER_NOT_SET: "not set",
    ParameterType.PARAMETER_BOOL: "bool",
    ParameterType.PARAMETER_INTEGER: "integer",
    ParameterType.PARAMETER_DOUBLE: "double",
    ParameterType.PARAMETER_STRING: "string",
    ParameterType.PARAMETER_BYTE_ARRAY: "byte array",
    ParameterType.PARAMETER_BOOL_ARRAY: "bool array",
    ParameterType.PARAMETER_INTEGER_ARRAY: "integer array",
    ParameterType.PARAMETER_DOUBLE_ARRAY: "double array",
    ParameterType.PARAMETER_STRING_ARRAY: "string array",
}


def python_value(value: ParameterValue) -> Any:
    """A ParameterValue as plain Python (None when not set).

    Untyped on purpose, not a union: callers check the kind they expect and use it.
    """
    entry = TYPE_WORDS.get(value.type)
    if entry is None:
        return None
    raw = getattr(value, entry[1])
    if hasattr(raw, "tolist"):
        raw = raw.tolist()
    if isinstance(raw, list | tuple):
        return [b[0] if isinstance(b, bytes) else b for b in raw]
    return raw


def parameter_value(value: object) -> ParameterValue:
    """Plain Python -> ParameterValue, with the type inferred as `ros2 param set` does."""
    out = ParameterValue()
    if isinstance(value, bool):
        out.type, out.bool_value = ParameterType.PARAMETER_BOOL, value
    elif isinstance(value, int):
        out.type, out.integer_value = ParameterType.PARAMETER_INTEGER, value
    elif isinstance(value, float):
        out.type, out.double_value = ParameterType.PARAMETER_DOUBLE, value
    elif isinstance(value, str):
        out.type, out.string_value = ParameterType.PARAMETER_STRING, value
    elif isinstance(value, list) and value:
        kinds = {type(v) for v in value}
        if kinds == {bool}:
            out.type, out.bool_array_value = ParameterType.PARAMETER_BOOL_ARRAY, value
        elif kinds == {int}:
            out.type, out.integer_array_value = ParameterType.PARAMETER_INTEGER_ARRAY, value
        elif kinds <= {int, float}:
            out.type = ParameterType.PARAMETER_DOUBLE_ARRAY
            out.double_array_value = [float(v) for v in value]
        elif kinds == {str}:
            out.type, out.string_array_value = ParameterType.PARAMETER_STRING_ARRAY, value
        else:
            raise Ros2Error("a parameter list must hold only booleans, numbers or strings")
    else:
        raise Ros2Error(f"cannot use {value!r} as a parameter value")
    return out


def parse_value(text: str) -> object:
    """'5' -> 5, 'true' -> True, '[1, 2]' -> [1, 2], anything else stays text."""
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        return text
    if value is None:
        return text
    return value


def _service(fqn: str, suffix: str) -> str:
    return f"{fqn.rstrip('/')}/{suffix}"


# Reading parameters is safe to repeat, so the readers below send an unanswered request
# once more, as set_value does (a new client's first answer can be lost: see call_service).
# Seen: the grader's read of a node's pose went unanswered on a loaded run, and its
# diagnosis ("the camera pose the node started with") was lost with it.


def _read(ctx: CallContext, fqn: str, suffix: str, srv_type: type, request: object) -> object:
    return call_service(ctx, _service(fqn, suffix), srv_type, request, resend_unanswered=True)


def list_names(ctx: CallContext, fqn: str) -> list[str]:
    request = ListParameters.Request()
    response = cast(
        ListParameters.Response, _read(ctx, fqn, "list_parameters", ListParameters, request)
    )
    return sorted(response.result.names)


def get_values(ctx: CallContext, fqn: str, names: list[str]) -> list[ParameterValue]:
    request = GetParameters.Request(names=names)
    response = cast(
        GetParameters.Response, _read(ctx, fqn, "get_parameters", GetParameters, request)
    )
    return list(response.values)


def describe(ctx: CallContext, fqn: str, names: list[str]) -> list[ParameterDescriptor]:
    request = DescribeParameters.Request(names=names)
    response = cast(
        DescribeParameters.Response,
        _read(ctx, fqn, "describe_parameters", DescribeParameters, request),
    )
    return list(response.descriptors)


def set_request(name: str, value: object) -> SetParameters.Request:
    """A request that sets one parameter, its type inferred as `ros2 param set` does."""
    return SetParameters.Request(parameters=[Parameter(name=name, value=parameter_value(value))])


def set_value(ctx: CallContext, fqn: str, name: str, value: object) -> tuple[bool, str]:
    """(successful, reason) as the node answered.

    Setting a value is safe to repeat, so an unanswered request is sent once more
    (a new client's first answer can be lost while discovery lags: see call_service).
    """
    request = set_request(name, value)
    service = _service(fqn, "set_parameters")
    response = cast(
        SetParameters.Response,
        call_service(ctx, service, SetParameters, request, resend_unanswered=True),
    )
    result = response.results[0]
    return bool(result.successful), result.reason


def dump_dict(ctx: CallContext, fqn: str) -> dict[str, object]:
    target = require_node(ctx, fqn)
    names = list_names(ctx, target)
    values = get_values(ctx, target, names) if names else []
    params: dict[str, object] = {}
    for name, value in zip(names, values, strict=False):
        node = params
        parts = name.split(".")
        for part in parts[:-1]:
            node = cast("dict[str, object]", node.setdefault(part, {}))
        node[parts[-1]] = python_value(value)
    return {target: {"ros__parameters": params}}


def same_value(actual: object, expected: object) -> bool:
    """Equality as a learner means it: 5 equals 5.0, floats compare with a tolerance."""
    numbers = (int, float)
    if isinstance(actual, bool) or isinstance(expected, bool):
        return bool(actual == expected)
    if isinstance(actual, numbers) and isinstance(expected, numbers):
        return math.isclose(actual, expected, rel_tol=1e-9, abs_tol=1e-12)
    return bool(actual == expected)
