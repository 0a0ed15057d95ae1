"""`ros2 node`, `ros2 service`, `ros2 action`: what is on the graph, and talking to it."""

from __future__ import annotations

from rclpy.action import (
    get_action_client_names_and_types_by_node,
    get_action_names_and_types,
    get_action_server_names_and_types_by_node,
)

from app.ros.calls import GoalRun, action_type_of, call_service, send_goal
from app.ros.context import CallContext
from app.ros.convert import from_yaml, import_type, message_repr, to_yaml
from app.ros.errors import Ros2Error
from app.ros.graph import all_nodes, require_node
from app.ros.names import ACTION_MARKER, split_node_name
from app.ros2cli.common import write_names

# ------------------------------------------------------------------- node


def node_list(ctx: CallContext, all_: bool = False, count: bool = False) -> int:
    return write_names(ctx, all_nodes(ctx.node, include_hidden=all_), count)


def _with_types(pairs: list[tuple[str, list[str]]], show_types: bool) -> list[str]:
    return [f"{name} [{', '.join(types)}]" if show_types else name for name, types in pairs]


def _visible(pairs: list[tuple[str, list[str]]]) -> list[tuple[str, list[str]]]:
    return sorted((n, t) for n, t in pairs if ACTION_MARKER not in n)


def node_info(ctx: CallContext, fqn: str) -> int:
    target = require_node(ctx, fqn)
    name, namespace = split_node_name(target)
    node = ctx.node
    sections = [
        ("Subscribers", _visible(node.get_subscriber_names_and_types_by_node(name, namespace))),
        ("Publishers", _visible(node.get_publisher_names_and_types_by_node(name, namespace))),
        ("Service Servers", _visible(node.get_service_names_and_types_by_node(name, namespace))),
        ("Service Clients", _visible(node.get_client_names_and_types_by_node(name, namespace))),
        ("Action Servers", get_action_server_names_and_types_by_node(node, name, namespace)),
        ("Action Clients", get_action_client_names_and_types_by_node(node, name, namespace)),
    ]
    ctx.write(target)
    for title, entries in sections:
        ctx.write(f"  {title}:")
        for entry, types in sorted(entries):
            ctx.write(f"    {entry}: {', '.join(types)}")
    return 0


# ---------------------------------------------------------------- service


def service_list(ctx: CallContext, show_types: bool = False, count: bool = False) -> int:
    services = _visible(ctx.node.get_service_names_and_types())
    return write_names(ctx, _with_types(services, show_types), count)


def service_type(ctx: CallContext, name: str) -> int:
    types = dict(ctx.node.get_service_names_and_types()).get(name)
    if not types:
        raise Ros2Error(f"unknown service '{name}' (see `ros2 service list`)")
    for type_text in types:
        ctx.write(type_text)
    return 0


def service_find(ctx: CallContext, type_text: str) -> int:
    services = _visible(ctx.node.get_service_names_and_types())
    return write_names(ctx, [name for name, types in services if type_text in types])


def service_info(ctx: CallContext, name: str) -> int:
    """Type and how many clients and servers, as Jazzy's `ros2 service info` prints them."""
    types = dict(ctx.node.get_service_names_and_types()).get(name)
    if not types:
        raise Ros2Error(f"unknown service '{name}' (see `ros2 service list`)")
    ctx.write(f"Type: {', '.join(types)}")
    ctx.write(f"Clients count: {ctx.node.count_clients(name)}")
    ctx.write(f"Services count: {ctx.node.count_services(name)}")
    return 0


def service_call(ctx: CallContext, name: str, type_text: str, values: str = "") -> int:
    srv_type = import_type(type_text, "srv")
    request = from_yaml(srv_type.Request, values)
    ctx.write(f"requester: making request: {message_repr(request)}")
    ctx.write("")
    response = call_service(ctx, name, srv_type, request)
    ctx.write("response:")
    ctx.write(message_repr(response))
    ctx.write("")
    return 0


# ----------------------------------------------------------------- action


def action_list(ctx: CallContext, show_types: bool = False, count: bool = False) -> int:
    actions = sorted(get_action_names_and_types(ctx.node))
    return write_names(ctx, _with_types(actions, show_types), count)


def action_type(ctx: CallContext, name: str) -> int:
    action_type = action_type_of(ctx.node, name)
    if action_type is None:
        raise Ros2Error(f"unknown action '{name}' (see `ros2 action list`)")
    ctx.write(action_type)
    return 0


def action_info(ctx: CallContext, name: str, show_types: bool = False) -> int:
    action_type = action_type_of(ctx.node, name)
    if action_type is None:
        raise Ros2Error(f"unknown action '{name}' (see `ros2 action list`)")
    clients, servers = [], []
    for fqn in all_nodes(ctx.node, include_hidden=True):
        node_name, namespace = split_node_name(fqn)
        try:
            srv = get_action_server_names_and_types_by_node(ctx.node, node_name, namespace)
            cli = get_action_client_names_and_types_by_node(ctx.node, node_name, namespace)
        except Exception:  # the node left the graph between the two calls
            continue
        if any(a == name for a, _t in srv):
            servers.append(fqn)
        if any(a == name for a, _t in cli):
            clients.append(fqn)
    suffix = f" [{action_type}]" if show_types else ""
    ctx.write(f"Action: {name}")
    ctx.write(f"Action clients: {len(clients)}")
    for fqn in clients:
        ctx.write(f"    {fqn}{suffix}")
    ctx.write(f"Action servers: {len(servers)}")
    for fqn in servers:
        ctx.write(f"    {fqn}{suffix}")
    return 0


def _indented(text: str, spaces: int = 4) -> str:
    return "\n".join(" " * spaces + line for line in text.splitlines())


def action_send_goal(
    ctx: CallContext, name: str, type_text: str, values: str = "", feedback: bool = False
) -> int:
    action_cls = import_type(type_text, "action")
    goal = from_yaml(action_cls.Goal, values)
    run = GoalRun(name, type_text, goal)
    ctx.write("Waiting for an action server to become available...")
    ctx.write("Sending goal:")
    ctx.write(_indented(to_yaml(goal), 5))
    ctx.write("")

    def on_accepted(run: GoalRun) -> None:
        ctx.write(f"Goal accepted with ID: {run.goal_id}")
        ctx.write("")

    def on_feedback(message) -> None:
        if feedback:
            ctx.write("Feedback:")
            ctx.write(_indented(to_yaml(message)))
            ctx.write("")

    send_goal(ctx, run, on_feedback, on_accepted)
    if run.status == "REJECTED":
        ctx.write("Goal was rejected.")
        return 1
    ctx.write("Result:")
    ctx.write(_indented(to_yaml(run.result)))
    ctx.write("")
    ctx.write(f"Goal finished with status: {run.status}")
    return 0 if run.status == "SUCCEEDED" else 1
