"""`ros2 param list/get/set/dump/load` (the parameter services themselves: app.ros.params)."""

from __future__ import annotations

import re
import time
from typing import cast

import yaml
from rcl_interfaces.msg import Parameter, ParameterDescriptor, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters

from app.ros.calls import call_service
from app.ros.context import CallContext
from app.ros.errors import Ros2Error
from app.ros.graph import all_nodes
from app.ros.params import (
    TYPE_WORDS,
    describe,
    dump_dict,
    get_values,
    list_names,
    parse_value,
    python_value,
    set_value,
)
from app.ros2cli.common import Commands, Ros2cliMessage, Verb, write_outcome, write_text
from app.ros2cli.graph_verbs import find_node
from app.ros2cli.options import (
    hidden_nodes_option,
    node_name_argument,
    strategy,
    timeout_option,
)
from app.ros2cli.run import params_file

# `ros2 param list --param-type` and `ros2 param describe` name the types so.
TYPE_WORDS_CLI = {
    ParameterType.PARAMETER_BOOL: "boolean",
    ParameterType.PARAMETER_INTEGER: "integer",
    ParameterType.PARAMETER_DOUBLE: "double",
    ParameterType.PARAMETER_STRING: "string",
    ParameterType.PARAMETER_BYTE_ARRAY: "byte array",
    ParameterType.PARAMETER_BOOL_ARRAY: "boolean array",
    ParameterType.PARAMETER_INTEGER_ARRAY: "integer array",
    ParameterType.PARAMETER_DOUBLE_ARRAY: "double array",
    ParameterType.PARAMETER_STRING_ARRAY: "string array",
    ParameterType.PARAMETER_NOT_SET: "not set",
}


def param_node(ctx: CallContext, fqn: str, include_hidden: bool = False) -> str:
    """The node's absolute name if it is on the graph, else ros2cli's 'Node not found'."""
    target = fqn if fqn.startswith("/") else "/" + fqn
    find_node(ctx, target, include_hidden, "Node not found")
    # As ros2cli's parameter client: the node's parameter services, within 5 s.
    wanted = f"{target.rstrip('/')}/list_parameters"
    deadline = time.monotonic() + ctx.limits.service_timeout
    while not any(n == wanted for n, _t in ctx.node.get_service_names_and_types()):
        if time.monotonic() > deadline:
            raise Ros2cliMessage(
                f"Wait for service timed out waiting for parameter services for node {target}"
            )
        ctx.sleep(0.1)
    return target


def param_list(
    ctx: CallContext,
    fqn: str | None = None,
    show_types: bool = False,
    include_hidden: bool = False,
    prefixes: list[str] | None = None,
    regex: str | None = None,
) -> int:
    targets = [param_node(ctx, fqn, include_hidden)] if fqn else all_nodes(ctx.node, include_hidden)
    pattern = re.compile(regex) if regex is not None else None
    for target in targets:
        try:
            names = list_names(ctx, target)
        except Ros2Error:
            if fqn:
                raise
            ctx.write(
                f"Wait for service timed out waiting for parameter services for node {target}"
            )
            continue
        if prefixes:
            names = [n for n in names if any(n == p or n.startswith(p + ".") for p in prefixes)]
        if pattern is not None:
            names = [n for n in names if pattern.match(n)]
        if not fqn and names:
            ctx.write(f"{target}:")
        types = {}
        if show_types and names:
            types = {
                n: TYPE_WORDS_CLI.get(d.type, "?")
                for n, d in zip(names, describe(ctx, target, names), strict=False)
            }
        for name in names:
            ctx.write(f"  {name} (type: {types[name]})" if show_types else f"  {name}")
    return 0


def param_get(
    ctx: CallContext, fqn: str, name: str, include_hidden: bool = False, hide_type: bool = False
) -> int:
    target = param_node(ctx, fqn, include_hidden)
    value = get_values(ctx, target, [name])
    if not value:
        raise Ros2cliMessage("Parameter not set")
    if value[0].type == ParameterType.PARAMETER_NOT_SET:
        ctx.write("None" if hide_type else "Parameter not set.")
        return 0
    words, _attr = TYPE_WORDS[value[0].type]
    shown = python_value(value[0])
    if value[0].type == ParameterType.PARAMETER_BYTE_ARRAY:
        shown = [bytes([b]) for b in shown]  # as rclpy hands byte values to ros2cli
    ctx.write(str(shown) if hide_type else f"{words}: {shown}")
    return 0


def param_set(
    ctx: CallContext, fqn: str, name: str, text: str, include_hidden: bool = False
) -> int:
    target = param_node(ctx, fqn, include_hidden)
    ok, reason = set_value(ctx, target, name, parse_value(text))
    words = "Set parameter successful" if ok else "Setting parameter failed"
    write_outcome(ctx, ok, words + (f": {reason}" if reason else ""))
    return 0  # ros2cli exits with 0 either way


def param_delete(ctx: CallContext, fqn: str, name: str, include_hidden: bool = False) -> int:
    """Set the parameter to 'not set' (what deleting is), and say how it went as ros2cli."""
    target = param_node(ctx, fqn, include_hidden)
    unset = ParameterValue(type=ParameterType.PARAMETER_NOT_SET)
    request = SetParameters.Request(parameters=[Parameter(name=name, value=unset)])
    service = f"{target.rstrip('/')}/set_parameters"
    response = cast(SetParameters.Response, call_service(ctx, service, SetParameters, request))
    result = response.results[0]
    words = "Deleted parameter successfully" if result.successful else "Deleting parameter failed"
    write_outcome(ctx, result.successful, words + (f": {result.reason}" if result.reason else ""))
    return 0


def describe_lines(descriptor: ParameterDescriptor) -> list[str]:
    """One parameter's descriptor as `ros2 param describe` prints it."""
    lines = [
        f"Parameter name: {descriptor.name}",
        f"  Type: {TYPE_WORDS_CLI.get(descriptor.type, '?')}",
    ]
    if descriptor.description:
        lines.append(f"  Description: {descriptor.description}")
    lines.append("  Constraints:")
    if descriptor.read_only:
        lines.append("    Read only: true")
    ranges = [*descriptor.floating_point_range, *descriptor.integer_range]
    if ranges:
        lines.append(f"    Min value: {ranges[0].from_value}")
        lines.append(f"    Max value: {ranges[0].to_value}")
        if ranges[0].step:
            lines.append(f"    Step: {ranges[0].step}")
    if descriptor.additional_constraints:
        lines.append(f"    Additional constraints: {descriptor.additional_constraints}")
    return lines


def param_describe(
    ctx: CallContext, fqn: str, names: list[str], include_hidden: bool = False
) -> int:
    target = param_node(ctx, fqn, include_hidden)
    for descriptor in describe(ctx, target, names):
        for line in describe_lines(descriptor):
            ctx.write(line)
    return 0


def param_dump(ctx: CallContext, fqn: str, include_hidden: bool = False) -> int:
    """ros2cli's dump: yaml.dump's defaults (sorted keys, block lists), then an empty line."""
    target = param_node(ctx, fqn, include_hidden)
    write_text(ctx, yaml.dump(dump_dict(ctx, target), default_flow_style=False))
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


def param_load(
    ctx: CallContext,
    fqn: str,
    file_text: str,
    include_hidden: bool = False,
    use_wildcard: bool = True,
) -> int:
    """Set every parameter a dump file holds for this node (or for every node: ``/**``)."""
    target = param_node(ctx, fqn, include_hidden)
    data = yaml.safe_load(params_file(file_text).read_text(encoding="utf-8"))
    sections = [
        section["ros__parameters"]
        for key, section in data.items()
        if key in (target, target.lstrip("/")) or (use_wildcard and key == "/**")
    ]
    if not sections:
        raise Ros2Error(f"{file_text!r} has no parameters for {target} (nor for /**)")
    for section in sections:
        for name, value in _flatten(section or {}).items():
            ok, reason = set_value(ctx, target, name, value)
            outcome = "successful" if ok else "failed"
            write_outcome(
                ctx, ok, f"Set parameter {name} {outcome}" + (f": {reason}" if reason else "")
            )
    return 0  # ros2cli exits with 0 even when a parameter was refused


# --- arguments: `ros2 param ...` as ros2cli takes them


def add_verbs(v: Commands, verb: Verb) -> None:
    p = verb(
        v,
        "list",
        "Output a list of available parameters",
        lambda c, a: param_list(
            c,
            a.node_name,
            a.param_type,
            a.include_hidden_nodes,
            a.param_prefixes,
            a.filter[0] if a.filter else None,
        ),
    )
    strategy(p)
    node_name_argument(p, optional=True)
    p.add_argument(
        "--filter",
        nargs=1,
        help="Only parameters matching the regex expression will be showed. "
        "Supports `re` regex syntax.",
    )
    hidden_nodes_option(p)
    p.add_argument(
        "--param-prefixes",
        nargs="+",
        default=[],
        help="Only list parameters with the provided prefixes",
    )
    p.add_argument(
        "--param-type", action="store_true", help="Print parameter types with parameter names"
    )

    p = verb(
        v,
        "get",
        "Get parameter",
        lambda c, a: param_get(
            c, a.node_name, a.parameter_name, a.include_hidden_nodes, a.hide_type
        ),
    )
    strategy(p)
    node_name_argument(p)
    hidden_nodes_option(p)
    p.add_argument("parameter_name", help="Name of the parameter")
    p.add_argument("--hide-type", action="store_true", help="Hide the type information")
    timeout_option(p)

    p = verb(
        v,
        "set",
        "Set parameter",
        lambda c, a: param_set(c, a.node_name, a.parameter_name, a.value, a.include_hidden_nodes),
    )
    strategy(p)
    node_name_argument(p)
    hidden_nodes_option(p)
    p.add_argument("parameter_name", help="Name of the parameter")
    p.add_argument("value", help="Value of the parameter")
    timeout_option(p)

    p = verb(
        v,
        "describe",
        "Show descriptive information about declared parameters",
        lambda c, a: param_describe(c, a.node_name, a.parameter_names, a.include_hidden_nodes),
    )
    strategy(p)
    node_name_argument(p)
    hidden_nodes_option(p)
    p.add_argument("parameter_names", nargs="+", help="Names of the parameters")
    timeout_option(p)

    p = verb(
        v,
        "dump",
        "Show all of the parameters of a node in a YAML file format",
        lambda c, a: param_dump(c, a.node_name, a.include_hidden_nodes),
    )
    strategy(p)
    node_name_argument(p)
    hidden_nodes_option(p)
    timeout_option(p)

    p = verb(
        v,
        "load",
        "Load parameter file for a node",
        lambda c, a: param_load(
            c, a.node_name, a.parameter_file, a.include_hidden_nodes, not a.no_use_wildcard
        ),
    )
    strategy(p)
    node_name_argument(p)
    hidden_nodes_option(p)
    p.add_argument("parameter_file", help="Parameter file")
    p.add_argument(
        "--no-use-wildcard",
        action="store_true",
        help="Do not load parameters in the '/**' namespace into the node",
    )
    timeout_option(p)

    p = verb(
        v,
        "delete",
        "Delete parameter",
        lambda c, a: param_delete(c, a.node_name, a.parameter_name, a.include_hidden_nodes),
    )
    strategy(p)
    node_name_argument(p)
    hidden_nodes_option(p)
    p.add_argument("parameter_name", help="Name of the parameter")
    timeout_option(p)
