"""`ros2 node`, `ros2 service`, `ros2 action`: what is on the graph, and talking to it."""

from __future__ import annotations

import argparse
import math
import threading
import time
from typing import cast

from rclpy.action import (
    get_action_client_names_and_types_by_node,
    get_action_names_and_types,
    get_action_server_names_and_types_by_node,
)
from rclpy.exceptions import InvalidTopicNameException
from rclpy.expand_topic_name import expand_topic_name
from rclpy.validate_full_topic_name import validate_full_topic_name
from rclpy.validate_topic_name import validate_topic_name

from app.ros.calls import (
    GoalRun,
    action_type_of,
    check_service_type,
    send_goal,
    wait_for_server,
    wait_future,
)
from app.ros.context import CallContext
from app.ros.convert import RosMessage, from_yaml, message_repr
from app.ros.errors import Cancelled
from app.ros.graph import all_nodes, wait_for_graph
from app.ros.names import split_node_name
from app.ros2cli.common import (
    Commands,
    Ros2cliMessage,
    SilentFailure,
    Verb,
    ros2_type,
    visible,
    write_names,
    write_note,
    write_text,
)
from app.ros2cli.msg_yaml import message_to_yaml
from app.ros2cli.options import node_listing_options, not_here, strategy

# ------------------------------------------------------------------- node


def node_list(ctx: CallContext, all_: bool = False, count: bool = False) -> int:
    names = all_nodes(ctx.node, include_hidden=all_)
    if not count and len(set(names)) < len(names):
        write_note(
            ctx,
            "WARNING: Be aware that there are nodes in the graph that share an exact "
            "name, which can have unintended side effects.",
        )
    return write_names(ctx, names, count)


def _with_types(pairs: list[tuple[str, list[str]]], show_types: bool) -> list[str]:
    return [f"{name} [{', '.join(types)}]" if show_types else name for name, types in pairs]


def find_node(ctx: CallContext, name: str, include_hidden: bool, message: str) -> str:
    """``name`` exactly as typed when it is on the graph, else ros2cli's ``message``.

    ros2cli compares the name as given (`ros2 node info talker` finds nothing);
    the param and lifecycle verbs first add the leading slash.
    """
    if not wait_for_graph(ctx, lambda: name in all_nodes(ctx.node, include_hidden=include_hidden)):
        raise Ros2cliMessage(message)
    return name


def node_info(ctx: CallContext, fqn: str, include_hidden: bool = False) -> int:
    """Six sections; an empty one still prints its (empty) list, as one empty line."""
    target = find_node(ctx, fqn, include_hidden, f"Unable to find node '{fqn}'")
    same = all_nodes(ctx.node, include_hidden=include_hidden).count(target)
    if same > 1:
        write_note(
            ctx,
            f'There are {same} nodes in the graph with the exact name "{target}". '
            "You are seeing information about only one of them.",
        )
    name, namespace = split_node_name(target)
    node = ctx.node
    sections = [
        ("Subscribers", node.get_subscriber_names_and_types_by_node(name, namespace)),
        ("Publishers", node.get_publisher_names_and_types_by_node(name, namespace)),
        ("Service Servers", node.get_service_names_and_types_by_node(name, namespace)),
        ("Service Clients", node.get_client_names_and_types_by_node(name, namespace)),
        ("Action Servers", get_action_server_names_and_types_by_node(node, name, namespace)),
        ("Action Clients", get_action_client_names_and_types_by_node(node, name, namespace)),
    ]
    ctx.write(target)
    for title, pairs in sections:
        ctx.write(f"  {title}:")
        entries = sorted(visible(pairs, include_hidden))
        for entry, types in entries:
            ctx.write(f"    {entry}: {', '.join(types)}")
        if not entries:
            ctx.write("")
    return 0


# ---------------------------------------------------------------- service


def _services(ctx: CallContext, include_hidden: bool) -> list[tuple[str, list[str]]]:
    return visible(ctx.node.get_service_names_and_types(), include_hidden)


def service_list(
    ctx: CallContext, show_types: bool = False, count: bool = False, include_hidden: bool = False
) -> int:
    return write_names(ctx, _with_types(_services(ctx, include_hidden), show_types), count)


def service_type(ctx: CallContext, name: str, include_hidden: bool = False) -> int:
    types = dict(_services(ctx, include_hidden)).get(name)
    if not types:
        raise SilentFailure(f"no service '{name}' on the graph")
    for type_text in types:
        ctx.write(type_text)
    return 0


def service_find(
    ctx: CallContext, type_text: str, count: bool = False, include_hidden: bool = False
) -> int:
    services = _services(ctx, include_hidden)
    return write_names(ctx, [name for name, types in services if type_text in types], count)


def _one_or_list(types: list[str]) -> str:
    """ros2cli prints a single type as text and several as a Python list."""
    return types[0] if len(types) == 1 else str(types)


def service_info(ctx: CallContext, name: str, include_hidden: bool = False) -> int:
    """Type and how many clients and servers, as Jazzy's `ros2 service info` prints them."""
    types = dict(_services(ctx, include_hidden)).get(name)
    if not types:
        raise Ros2cliMessage(f"Unknown service '{name}'")
    ctx.write(f"Type: {_one_or_list(types)}")
    ctx.write(f"Clients count: {ctx.node.count_clients(name)}")
    ctx.write(f"Services count: {ctx.node.count_services(name)}")
    return 0


def service_call(
    ctx: CallContext, name: str, type_text: str, values: str = "", rate: float | None = None
) -> int:
    """ros2cli's lines: waiting... (only if the server is not matched yet), then per call the
    request's repr, an empty line, 'response:', the response's repr and an empty line."""
    if rate is not None and not rate > 0:
        raise Ros2cliMessage("rate must be greater than zero")
    srv_type = ros2_type(type_text, "srv")
    request = from_yaml(srv_type.Request, values)
    validate_topic_name(name, is_service=True)  # before any line, as ros2's client does
    check_service_type(ctx, name, srv_type)
    client = ctx.node.create_client(srv_type, name)
    try:
        if not client.service_is_ready():
            ctx.write("waiting for service to become available...")
            timeout = ctx.limits.service_timeout
            wait_for_server(ctx, client.service_is_ready, timeout, f"service '{name}'")
        deadline = time.monotonic() + ctx.limits.max_seconds if ctx.limits.max_seconds else math.inf
        while True:
            ctx.write(f"requester: making request: {message_repr(request)}")
            ctx.write("")
            started = time.monotonic()
            future = client.call_async(request)
            response = wait_future(ctx, future, ctx.limits.service_timeout, f"service '{name}'")
            ctx.write("response:")
            ctx.write(message_repr(response))
            ctx.write("")
            if rate is None:
                return 0
            next_call = started + 1.0 / rate
            if next_call > deadline:
                return 0
            ctx.sleep(max(0.0, next_call - time.monotonic()))
    finally:
        ctx.node.destroy_client(client)


# ----------------------------------------------------------------- action


def action_list(ctx: CallContext, show_types: bool = False, count: bool = False) -> int:
    actions = sorted(get_action_names_and_types(ctx.node))
    return write_names(ctx, _with_types(actions, show_types), count)


def action_type(ctx: CallContext, name: str) -> int:
    action_type = action_type_of(ctx.node, name)
    if action_type is None:
        raise SilentFailure(f"no action '{name}' on the graph")
    ctx.write(action_type)
    return 0


def action_info(ctx: CallContext, name: str, show_types: bool = False, count: bool = False) -> int:
    """Clients and servers of an action (an unknown action simply has none, as in ros2cli)."""
    try:  # a relative name counts from our node, and a malformed one is refused, as ros2cli
        expanded = expand_topic_name(name, ctx.node.get_name(), ctx.node.get_namespace())
        validate_full_topic_name(expanded)
    except (ValueError, InvalidTopicNameException) as exc:
        raise Ros2cliMessage(str(exc)) from None
    clients: list[tuple[str, list[str]]] = []
    servers: list[tuple[str, list[str]]] = []
    for fqn in all_nodes(ctx.node, include_hidden=True):
        node_name, namespace = split_node_name(fqn)
        try:
            srv = get_action_server_names_and_types_by_node(ctx.node, node_name, namespace)
            cli = get_action_client_names_and_types_by_node(ctx.node, node_name, namespace)
        except Exception:  # the node left the graph between the two calls
            continue
        servers += [(fqn, list(t)) for a, t in srv if a == expanded]
        clients += [(fqn, list(t)) for a, t in cli if a == expanded]
    ctx.write(f"Action: {name}")
    for title, found in (("Action clients", clients), ("Action servers", servers)):
        ctx.write(f"{title}: {len(found)}")
        for fqn, types in [] if count else found:
            ctx.write(f"    {fqn} [{', '.join(types)}]" if show_types else f"    {fqn}")
    return 0


def write_message_block(ctx: CallContext, title: str, msg: object, indent: int) -> None:
    """ros2cli's "Title:\n<indent><yaml>": only the YAML's first line is indented."""
    ctx.write(f"{title}:")
    write_text(ctx, " " * indent + message_to_yaml(cast(RosMessage, msg)))  # a goal, ...


def action_send_goal(
    ctx: CallContext, name: str, type_text: str, values: str = "", feedback: bool = False
) -> int:
    """The lines `ros2 action send_goal` prints; its exit code is 0 whatever the goal's fate."""
    action_cls = ros2_type(type_text, "action")
    goal = from_yaml(action_cls.Goal, values)
    run = GoalRun(name, type_text, goal)
    ctx.write("Waiting for an action server to become available...")
    # ros2 prints the goal once a server is there: wait for one on the graph first.
    timeout = ctx.limits.service_timeout
    wait_for_server(
        ctx,
        lambda: any(n == name for n, _t in get_action_names_and_types(ctx.node)),
        timeout,
        f"action server '{name}'",
    )
    write_message_block(ctx, "Sending goal", goal, 5)

    # As ros2cli, each line when its event is handled: feedback that comes with the
    # acceptance (handled first by rclpy's action client) prints before "Goal accepted".
    lock = threading.Lock()

    def on_accepted(run: GoalRun) -> None:
        with lock:
            ctx.write(f"Goal accepted with ID: {run.goal_id}")
            ctx.write("")

    def on_feedback(message: object) -> None:
        if feedback:
            with lock:
                write_message_block(ctx, "Feedback", message, 4)

    try:
        send_goal(ctx, run, on_feedback, on_accepted)
    except Cancelled:
        if run.goal_id:  # accepted and running: send_goal has asked the server to cancel it
            ctx.write("Canceling goal...")
        raise
    if run.status == "REJECTED":
        ctx.write("Goal was rejected.")
        return 0
    write_message_block(ctx, "Result", run.result, 4)
    ctx.write(f"Goal finished with status: {run.status}")
    return 0


# --- arguments: `ros2 node/service/action ...` as ros2cli takes them


def add_node_verbs(v: Commands, verb: Verb) -> None:
    p = verb(
        v,
        "list",
        "Output a list of available nodes",
        lambda c, a: node_list(c, a.all, a.count_nodes),
    )
    node_listing_options(p)
    p = verb(
        v,
        "info",
        "Output information about a node",
        lambda c, a: node_info(c, a.node_name, a.include_hidden),
    )
    strategy(p)
    p.add_argument("node_name", help="Node name to request information")
    p.add_argument(
        "--include-hidden",
        action="store_true",
        help="Display hidden topics, services, and actions as well",
    )


def _count_services(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "-c",
        "--count-services",
        action="store_true",
        help="Only display the number of services discovered",
    )
    p.add_argument(
        "--include-hidden-services", action="store_true", help="Consider hidden services as well"
    )


def add_service_verbs(v: Commands, verb: Verb) -> None:
    p = verb(
        v,
        "list",
        "Output a list of available services",
        lambda c, a: service_list(c, a.show_types, a.count_services, a.include_hidden_services),
    )
    strategy(p)
    p.add_argument(
        "-t", "--show-types", action="store_true", help="Additionally show the service type"
    )
    _count_services(p)

    p = verb(
        v,
        "type",
        "Output a service's type",
        lambda c, a: service_type(c, a.service_name, a.include_hidden_services),
    )
    p.add_argument(
        "service_name",
        help="Name of the ROS service to get type (e.g. '/talker/list_parameters')",
    )

    p = verb(
        v,
        "find",
        "Output a list of available services of a given type",
        lambda c, a: service_find(c, a.service_type, a.count_services, a.include_hidden_services),
    )
    p.add_argument(
        "service_type",
        help="Name of the ROS service type to filter for "
        "(e.g. 'rcl_interfaces/srv/ListParameters')",
    )
    _count_services(p)

    p = verb(
        v,
        "info",
        "Print information about a service",
        lambda c, a: service_info(c, a.service_name, a.include_hidden_services),
    )
    strategy(p)
    p.add_argument(
        "service_name", help="Name of the ROS service to get info (e.g. '/add_two_ints')"
    )

    p = verb(
        v,
        "call",
        "Call a service",
        lambda c, a: service_call(c, a.service_name, a.service_type, a.values, rate=a.rate),
    )
    p.add_argument("service_name", help="Name of the ROS service to call to (e.g. '/add_two_ints')")
    p.add_argument("service_type", help="Type of the ROS service (e.g. 'std_srvs/srv/Empty')")
    values_or_stdin = p.add_mutually_exclusive_group()
    values_or_stdin.add_argument(
        "values",
        nargs="?",
        default="{}",
        help="Values to fill the service request with in YAML format (e.g. '{a: 1, b: 2}'), "
        "otherwise the service request will be published with default values",
    )
    not_here(p, "--stdin", flag=True, group=values_or_stdin, help="Read values from standard input")
    p.add_argument(
        "-r",
        "--rate",
        metavar="N",
        type=float,
        default=None,
        help="Repeat the call at a specific rate in Hz",
    )


def add_action_verbs(v: Commands, verb: Verb) -> None:
    p = verb(
        v,
        "list",
        "Output a list of action names",
        lambda c, a: action_list(c, a.show_types, a.count_actions),
    )
    p.add_argument(
        "-t", "--show-types", action="store_true", help="Additionally show the action type"
    )
    p.add_argument(
        "-c",
        "--count-actions",
        action="store_true",
        help="Only display the number of actions discovered",
    )
    # (sic: "a action's", and the example of `action type` says "get info")
    p = verb(v, "type", "Print a action's type", lambda c, a: action_type(c, a.action_name))
    p.add_argument("action_name", help="Name of the ROS action to get info (e.g. '/fibonacci')")
    p = verb(
        v,
        "info",
        "Print information about an action",
        lambda c, a: action_info(c, a.action_name, a.show_types, a.count),
    )
    p.add_argument("action_name", help="Name of the ROS action to get info (e.g. '/fibonacci')")
    p.add_argument(
        "-t", "--show-types", action="store_true", help="Additionally show the action type"
    )
    p.add_argument(
        "-c",
        "--count",
        action="store_true",
        help="Only display the number of action clients and action servers",
    )
    p = verb(
        v,
        "send_goal",
        "Send an action goal",
        lambda c, a: action_send_goal(c, a.action_name, a.action_type, a.goal, a.feedback),
    )
    p.add_argument("action_name", help="Name of the ROS action (e.g. '/fibonacci')")
    p.add_argument(
        "action_type", help="Type of the ROS action (e.g. 'example_interfaces/action/Fibonacci')"
    )
    goal_or_stdin = p.add_mutually_exclusive_group()
    goal_or_stdin.add_argument(
        "goal",
        nargs="?",
        default="{}",
        help="Goal request values in YAML format (e.g. '{order: 10}')",
    )
    not_here(p, "--stdin", flag=True, group=goal_or_stdin, help="Read goal from standard input")
    p.add_argument(
        "-f", "--feedback", action="store_true", help="Echo feedback messages for the goal"
    )
