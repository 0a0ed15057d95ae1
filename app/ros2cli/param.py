"""`ros2 param list/get/set/dump/load` (the parameter services themselves: app.ros.params)."""

from __future__ import annotations

import yaml
from rcl_interfaces.msg import ParameterType

from app.ros.context import CallContext
from app.ros.convert import dump_yaml
from app.ros.errors import Ros2Error
from app.ros.graph import all_nodes, require_node
from app.ros.params import (
    TYPE_NAMES,
    TYPE_WORDS,
    describe,
    dump_dict,
    get_values,
    list_names,
    parse_value,
    python_value,
    set_value,
)
from app.ros2cli.run import params_file


def param_list(ctx: CallContext, fqn: str | None = None, show_types: bool = False) -> int:
    targets = [require_node(ctx, fqn)] if fqn else all_nodes(ctx.node)
    for target in targets:
        try:
            names = list_names(ctx, target)
        except Ros2Error as exc:
            if fqn:
                raise
            ctx.write(f"{target}: ({exc})")
            continue
        if not fqn:
            ctx.write(f"{target}:")
        types = {}
        if show_types and names:
            types = {
                n: TYPE_NAMES.get(d.type, "?")
                for n, d in zip(names, describe(ctx, target, names), strict=False)
            }
        for name in names:
            ctx.write(f"  {name}" + (f" (type: {types[name]})" if show_types else ""))
    return 0


def param_get(ctx: CallContext, fqn: str, name: str) -> int:
    target = require_node(ctx, fqn)
    value = get_values(ctx, target, [name])
    if not value or value[0].type == ParameterType.PARAMETER_NOT_SET:
        ctx.write("Parameter not set.")
        return 1
    words, _attr = TYPE_WORDS[value[0].type]
    ctx.write(f"{words}: {python_value(value[0])}")
    return 0


def param_set(ctx: CallContext, fqn: str, name: str, text: str) -> int:
    target = require_node(ctx, fqn)
    ok, reason = set_value(ctx, target, name, parse_value(text))
    if ok:
        ctx.write("Set parameter successful" + (f": {reason}" if reason else ""))
        return 0
    ctx.write("Set parameter failed" + (f": {reason}" if reason else ""))
    return 1


def param_dump(ctx: CallContext, fqn: str) -> int:
    text = dump_yaml(dump_dict(ctx, fqn))
    for line in text.rstrip().splitlines():
        ctx.write(line)
    return 0


def _flatten(values: dict, prefix: str = "") -> dict:
    """Nested YAML maps -> dotted parameter names, as a dump nests them."""
    flat: dict = {}
    for key, value in values.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            flat.update(_flatten(value, f"{name}."))
        else:
            flat[name] = value
    return flat


def param_load(ctx: CallContext, fqn: str, file_text: str) -> int:
    """Set every parameter a dump file holds for this node (or for every node: ``/**``)."""
    target = require_node(ctx, fqn)
    data = yaml.safe_load(params_file(file_text).read_text(encoding="utf-8"))
    sections = [
        section["ros__parameters"]
        for key, section in data.items()
        if key in ("/**", target, target.lstrip("/"))
    ]
    if not sections:
        raise Ros2Error(f"{file_text!r} has no parameters for {target} (nor for /**)")
    failed = False
    for section in sections:
        for name, value in _flatten(section or {}).items():
            ok, reason = set_value(ctx, target, name, value)
            failed |= not ok
            outcome = "successful" if ok else "failed"
            ctx.write(f"Set parameter {name} {outcome}" + (f": {reason}" if reason else ""))
    return 1 if failed else 0
