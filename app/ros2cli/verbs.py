"""The arguments of `ros2 node/topic/service/action/param/lifecycle/interface` verbs.

Option names, short forms and defaults follow Jazzy's ros2cli, so ``-h`` shows
what a learner finds in the docs. Options ros2cli has but we do not are named
in each verb's help (``Not supported here: ...``): typing one gives argparse's
"unrecognized arguments" error instead of being silently ignored.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

from app.ros2cli import graph_verbs, lifecycle, param, topic

# ros2cli's "strategy" options (daemon and discovery): accepted, nothing to do here.
_STRATEGY_UNSUPPORTED = ("-s/--use-sim-time",)
_QOS = (
    "--qos-profile",
    "--qos-depth",
    "--qos-history",
    "--qos-reliability",
    "--qos-durability",
    "--qos-liveliness",
    "--qos-liveliness-lease-duration-seconds",
)

Verb = Callable[..., argparse.ArgumentParser]


def unsupported(p: argparse.ArgumentParser, *options: str) -> None:
    """Name in -h the options Jazzy's ros2 has for this verb that we do not offer."""
    if options:
        p.epilog = (
            "Not supported here (Jazzy's ros2 has them): "
            + ", ".join(options)
            + ". Using one gives an 'unrecognized arguments' error."
        )
        p.formatter_class = argparse.RawDescriptionHelpFormatter


def strategy(p: argparse.ArgumentParser) -> None:
    """--spin-time and --no-daemon: accepted (a fresh CLI node always discovers the graph)."""
    p.add_argument(
        "--spin-time",
        type=float,
        default=None,
        help="Spin time in seconds to wait for discovery (accepted; "
        "the CLI waits until the graph stops changing)",
    )
    p.add_argument(
        "--no-daemon",
        action="store_true",
        help="Do not use a daemon (there is none here: always true)",
    )


def _node_listing_options(p: Any) -> None:
    """`ros2 node list` and `ros2 lifecycle nodes` take the same options."""
    strategy(p)
    p.add_argument("-a", "--all", action="store_true", help="Display all nodes even hidden ones")
    p.add_argument(
        "-c",
        "--count-nodes",
        action="store_true",
        help="Only display the number of nodes discovered",
    )
    unsupported(p, *_STRATEGY_UNSUPPORTED)


def add_node(v: Any, verb: Verb) -> None:
    p = verb(
        v,
        "list",
        "Output a list of available nodes",
        lambda c, a: graph_verbs.node_list(c, a.all, a.count_nodes),
    )
    _node_listing_options(p)
    p = verb(
        v,
        "info",
        "Output information about a node",
        lambda c, a: graph_verbs.node_info(c, a.node_name, a.include_hidden),
    )
    strategy(p)
    p.add_argument("node_name", help="Node name to request information")
    p.add_argument(
        "--include-hidden",
        action="store_true",
        help="Display hidden topics, services, and actions as well",
    )
    unsupported(p, *_STRATEGY_UNSUPPORTED)


def _topic_and_type(p: argparse.ArgumentParser) -> None:
    p.add_argument("topic_name", help="Name of the ROS topic (e.g. '/chatter')")
    p.add_argument(
        "message_type", nargs="?", help="Type of the ROS message (e.g. 'std_msgs/msg/String')"
    )


def add_topic(v: Any, verb: Verb) -> None:
    hidden_help = "Consider hidden topics as well"
    p = verb(
        v,
        "list",
        "Output a list of available topics",
        lambda c, a: topic.list_topics(
            c, a.show_types, a.verbose, a.count_topics, a.include_hidden_topics
        ),
    )
    strategy(p)
    p.add_argument(
        "-t", "--show-types", action="store_true", help="Additionally show the topic type"
    )
    p.add_argument(
        "-c",
        "--count-topics",
        action="store_true",
        help="Only display the number of topics discovered",
    )
    p.add_argument("--include-hidden-topics", action="store_true", help=hidden_help)
    p.add_argument(
        "-v", "--verbose", action="store_true", help="List full details about each topic"
    )
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "info",
        "Print information about a topic",
        lambda c, a: topic.topic_info(c, a.topic_name, a.verbose),
    )
    strategy(p)
    p.add_argument("topic_name", help="Name of the ROS topic to get info (e.g. '/chatter')")
    p.add_argument(
        "-v",
        "--verbose",
        action="store_true",
        help="Print the node name, node namespace, topic type, topic type hash, GID "
        "and QoS profile of each publisher and subscription",
    )
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "type",
        "Print a topic's type",
        lambda c, a: topic.topic_type(c, a.topic_name, a.include_hidden_topics),
    )
    strategy(p)
    p.add_argument("topic_name", help="Name of the ROS topic to get type (e.g. '/chatter')")
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "find",
        "Output a list of available topics of a given type",
        lambda c, a: topic.find(c, a.topic_type, a.count_topics, a.include_hidden_topics),
    )
    strategy(p)
    p.add_argument(
        "topic_type", help="Name of the ROS topic type to filter for (e.g. 'std_msgs/msg/String')"
    )
    p.add_argument(
        "-c",
        "--count-topics",
        action="store_true",
        help="Only display the number of topics discovered",
    )
    p.add_argument("--include-hidden-topics", action="store_true", help=hidden_help)
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "echo",
        "Output messages from a topic",
        lambda c, a: topic.echo(
            c,
            a.topic_name,
            a.message_type,
            once=a.once,
            field=a.field,
            style=topic.EchoStyle(
                truncate_length=None if a.full_length else a.truncate_length,
                no_arr=a.no_arr,
                no_str=a.no_str,
                flow_style=a.flow_style,
                csv=a.csv,
            ),
            timeout=a.timeout,
        ),
    )
    strategy(p)
    _topic_and_type(p)
    p.add_argument(
        "--field",
        default=None,
        help="Echo a selected field of a message. Use '.' to select sub-fields "
        "(e.g. 'pose.pose.position')",
    )
    p.add_argument(
        "-f",
        "--full-length",
        action="store_true",
        help="Output all elements of arrays, bytes and strings (no truncation)",
    )
    p.add_argument(
        "-l",
        "--truncate-length",
        type=int,
        default=128,
        help="The length to truncate arrays, bytes, and string to (default: 128)",
    )
    p.add_argument("--no-arr", action="store_true", help="Don't print array fields of messages")
    p.add_argument("--no-str", action="store_true", help="Don't print string fields of messages")
    p.add_argument(
        "--flow-style",
        action="store_true",
        help="Print collections in the flow style (not available with csv format)",
    )
    p.add_argument(
        "--csv",
        action="store_true",
        help="Output all recursive fields separated by commas (e.g. for plotting)",
    )
    p.add_argument(
        "--once", action="store_true", help="Print the first message received and then exit."
    )
    p.add_argument(
        "--timeout",
        metavar="N",
        type=float,
        default=None,
        help="Set a timeout in seconds for waiting",
    )
    unsupported(
        p,
        *_QOS,
        "--no-lost-messages",
        "--raw",
        "--filter",
        "-i/--include-message-info",
        *_STRATEGY_UNSUPPORTED,
    )

    for name, help_text, measure, window in (
        ("hz", "Print the average publishing rate to screen", topic.hz, 10_000),
        ("bw", "Display bandwidth used by topic", topic.bw, 100),
    ):
        p = verb(
            v,
            name,
            help_text,
            lambda c, a, m=measure: m(c, a.topic_name, a.message_type, a.window),
        )
        strategy(p)
        _topic_and_type(p)
        p.add_argument(
            "-w",
            "--window",
            type=int,
            default=window,
            metavar="WINDOW",
            help=f"window size, in # of messages, for calculating rate (default: {window})",
        )
        unsupported(
            p, *(("--filter", "--wall-time") if name == "hz" else ()), *_STRATEGY_UNSUPPORTED
        )

    p = verb(
        v,
        "pub",
        "Publish a message to a topic",
        lambda c, a: topic.pub(
            c,
            a.topic_name,
            a.message_type,
            a.values,
            once=a.once,
            rate=a.rate,
            times=a.times,
            wait_matching=a.wait_matching_subscriptions,
            print_nth=a.print,
            max_wait_time=a.max_wait_time_secs,
            keep_alive=a.keep_alive,
        ),
    )
    p.add_argument("topic_name", help="Name of the ROS topic to publish to (e.g. '/chatter')")
    p.add_argument("message_type", help="Type of the ROS message (e.g. 'std_msgs/String')")
    p.add_argument(
        "values",
        nargs="?",
        default="{}",
        help="Values to fill the message with in YAML format (e.g. 'data: Hello World'), "
        "otherwise the message will be published with default values",
    )
    p.add_argument(
        "-r",
        "--rate",
        metavar="N",
        type=float,
        default=1.0,
        help="Publishing rate in Hz (default: 1)",
    )
    p.add_argument(
        "-p",
        "--print",
        metavar="N",
        type=int,
        default=1,
        help="Only print every N-th published message (default: 1)",
    )
    once_or_times = p.add_mutually_exclusive_group()
    once_or_times.add_argument(
        "-1", "--once", action="store_true", help="Publish one message and exit"
    )
    once_or_times.add_argument(
        "-t", "--times", type=int, default=0, help="Publish this number of times and then exit"
    )
    p.add_argument(
        "-w",
        "--wait-matching-subscriptions",
        type=int,
        default=None,
        help="Wait until finding the specified number of matching subscriptions. "
        'Defaults to 1 when using "-1"/"--once"/"--times", otherwise defaults to 0.',
    )
    p.add_argument(
        "--max-wait-time-secs",
        type=float,
        default=None,
        help="The maximum wait time in seconds for matching subscriptions "
        "(default: wait endlessly)",
    )
    p.add_argument(
        "--keep-alive",
        metavar="N",
        type=float,
        default=0.1,
        help="Keep publishing node alive for N seconds after the last msg (default: 0.1)",
    )
    unsupported(p, "--stdin", "-n/--node-name", *_QOS, *_STRATEGY_UNSUPPORTED)


def _service_list_like(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "-c",
        "--count-services",
        action="store_true",
        help="Only display the number of services discovered",
    )
    p.add_argument(
        "--include-hidden-services", action="store_true", help="Consider hidden services as well"
    )


def add_service(v: Any, verb: Verb) -> None:
    p = verb(
        v,
        "list",
        "Output a list of available services",
        lambda c, a: graph_verbs.service_list(
            c, a.show_types, a.count_services, a.include_hidden_services
        ),
    )
    strategy(p)
    p.add_argument(
        "-t", "--show-types", action="store_true", help="Additionally show the service type"
    )
    _service_list_like(p)
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "type",
        "Output a service's type",
        lambda c, a: graph_verbs.service_type(c, a.service_name, a.include_hidden_services),
    )
    p.add_argument("service_name", help="Name of the ROS service to get type")

    p = verb(
        v,
        "find",
        "Output a list of available services of a given type",
        lambda c, a: graph_verbs.service_find(
            c, a.service_type, a.count_services, a.include_hidden_services
        ),
    )
    p.add_argument(
        "service_type",
        help="Name of the ROS service type to filter for "
        "(e.g. 'rcl_interfaces/srv/ListParameters')",
    )
    _service_list_like(p)

    p = verb(
        v,
        "info",
        "Print information about a service",
        lambda c, a: graph_verbs.service_info(c, a.service_name, a.include_hidden_services),
    )
    strategy(p)
    p.add_argument(
        "service_name", help="Name of the ROS service to get info (e.g. '/add_two_ints')"
    )
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "call",
        "Call a service",
        lambda c, a: graph_verbs.service_call(
            c, a.service_name, a.service_type, a.values, rate=a.rate
        ),
    )
    p.add_argument("service_name", help="Name of the ROS service to call to (e.g. '/add_two_ints')")
    p.add_argument("service_type", help="Type of the ROS service (e.g. 'std_srvs/srv/Empty')")
    p.add_argument(
        "values",
        nargs="?",
        default="{}",
        help="Values to fill the service request with in YAML format (e.g. '{a: 1, b: 2}'), "
        "otherwise the service request will be published with default values",
    )
    p.add_argument(
        "-r",
        "--rate",
        metavar="N",
        type=float,
        default=None,
        help="Repeat the call at a specific rate in Hz",
    )
    unsupported(p, "--stdin")


def add_action(v: Any, verb: Verb) -> None:
    p = verb(
        v,
        "list",
        "Output a list of action names",
        lambda c, a: graph_verbs.action_list(c, a.show_types, a.count_actions),
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
    p = verb(
        v, "type", "Print a ROS action type", lambda c, a: graph_verbs.action_type(c, a.action_name)
    )
    p.add_argument("action_name", help="Name of the ROS action to get type (e.g. '/fibonacci')")
    p = verb(
        v,
        "info",
        "Print information about an action",
        lambda c, a: graph_verbs.action_info(c, a.action_name, a.show_types, a.count),
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
        lambda c, a: graph_verbs.action_send_goal(
            c, a.action_name, a.action_type, a.goal, a.feedback
        ),
    )
    p.add_argument("action_name", help="Name of the ROS action (e.g. '/fibonacci')")
    p.add_argument(
        "action_type", help="Type of the ROS action (e.g. 'example_interfaces/action/Fibonacci')"
    )
    p.add_argument(
        "goal",
        nargs="?",
        default="{}",
        help="Goal request values in YAML format (e.g. '{order: 10}')",
    )
    p.add_argument(
        "-f", "--feedback", action="store_true", help="Echo feedback messages for the goal"
    )
    unsupported(p, "--stdin")


def _param_node(p: argparse.ArgumentParser, optional: bool = False) -> None:
    strategy(p)
    p.add_argument("node_name", nargs="?" if optional else None, help="Name of the ROS node")
    p.add_argument(
        "--include-hidden-nodes", action="store_true", help="Consider hidden nodes as well"
    )


def _timeout(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--timeout",
        metavar="N",
        type=int,
        default=1,
        help="Wait for N seconds until node becomes available (default 1 sec)",
    )


def add_param(v: Any, verb: Verb) -> None:
    p = verb(
        v,
        "list",
        "Output a list of available parameters",
        lambda c, a: param.param_list(
            c, a.node_name, a.param_type, a.include_hidden_nodes, a.param_prefixes, a.filter
        ),
    )
    _param_node(p, optional=True)
    p.add_argument("--filter", default=None, help="Only parameters matching the regex expression")
    p.add_argument(
        "--param-prefixes",
        nargs="+",
        default=[],
        help="Only list parameters with the provided prefixes",
    )
    p.add_argument(
        "--param-type", action="store_true", help="Print parameter types with parameter names"
    )
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "get",
        "Get parameter",
        lambda c, a: param.param_get(
            c, a.node_name, a.parameter_name, a.include_hidden_nodes, a.hide_type
        ),
    )
    _param_node(p)
    p.add_argument("parameter_name", help="Name of the parameter")
    p.add_argument("--hide-type", action="store_true", help="Hide the type information")
    _timeout(p)
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "set",
        "Set parameter",
        lambda c, a: param.param_set(
            c, a.node_name, a.parameter_name, a.value, a.include_hidden_nodes
        ),
    )
    _param_node(p)
    p.add_argument("parameter_name", help="Name of the parameter")
    p.add_argument("value", help="Value of the parameter")
    _timeout(p)
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "describe",
        "Show descriptive information about declared parameters",
        lambda c, a: param.param_describe(
            c, a.node_name, a.parameter_names, a.include_hidden_nodes
        ),
    )
    _param_node(p)
    p.add_argument("parameter_names", nargs="+", help="Names of the parameters")
    _timeout(p)
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "dump",
        "Show all of the parameters of a node in a YAML file format",
        lambda c, a: param.param_dump(c, a.node_name, a.include_hidden_nodes),
    )
    _param_node(p)
    _timeout(p)
    unsupported(p, "--output-dir", "--print", *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "load",
        "Load parameter file for a node",
        lambda c, a: param.param_load(
            c, a.node_name, a.parameter_file, a.include_hidden_nodes, not a.no_use_wildcard
        ),
    )
    _param_node(p)
    p.add_argument("parameter_file", help="Parameter file")
    _timeout(p)
    p.add_argument(
        "--no-use-wildcard",
        action="store_true",
        help="Do not load parameters in the '/**' namespace into the node",
    )
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "delete",
        "Delete parameter",
        lambda c, a: param.param_delete(c, a.node_name, a.parameter_name, a.include_hidden_nodes),
    )
    _param_node(p)
    p.add_argument("parameter_name", help="Name of the parameter")
    _timeout(p)
    unsupported(p, *_STRATEGY_UNSUPPORTED)


def add_lifecycle(v: Any, verb: Verb) -> None:
    p = verb(
        v,
        "nodes",
        "Output a list of nodes with lifecycle",
        lambda c, a: lifecycle.verb_nodes(c, a.count_nodes, a.all),
    )
    _node_listing_options(p)

    p = verb(
        v,
        "get",
        "Get lifecycle state for one or more nodes",
        lambda c, a: lifecycle.verb_get(c, a.node_name, a.include_hidden_nodes),
    )
    _param_node(p, optional=True)
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "list",
        "Output a list of available transitions",
        lambda c, a: lifecycle.verb_list(c, a.node_name, a.include_hidden_nodes, a.all),
    )
    _param_node(p)
    p.add_argument("-a", "--all", action="store_true", help="Display all existing transitions")
    unsupported(p, *_STRATEGY_UNSUPPORTED)

    p = verb(
        v,
        "set",
        "Trigger lifecycle state transition",
        lambda c, a: lifecycle.verb_set(c, a.node_name, a.transition, a.include_hidden_nodes),
    )
    _param_node(p)
    p.add_argument("transition", help="The lifecycle transition")
    unsupported(p, *_STRATEGY_UNSUPPORTED)


def only_kinds(p: argparse.ArgumentParser) -> None:
    """`ros2 interface package(s)`: -m, -s, -a."""
    p.add_argument("-m", "--only-msgs", action="store_true", help="Only message types")
    p.add_argument("-s", "--only-srvs", action="store_true", help="Only service types")
    p.add_argument("-a", "--only-actions", action="store_true", help="Only action types")


def comment_options(p: argparse.ArgumentParser) -> None:
    """`ros2 interface show`: --all-comments or --no-comments."""
    group = p.add_mutually_exclusive_group()
    group.add_argument(
        "--all-comments",
        action="store_true",
        help="Show all comments, including for nested interface definitions",
    )
    group.add_argument("--no-comments", action="store_true", help="Show no comments or whitespace")


def command_options(group: str, p: argparse.ArgumentParser) -> None:
    """Options ros2 takes before the verb: `ros2 topic --include-hidden-topics type /x`."""
    noun = {"topic": "topics", "service": "services"}.get(group)
    if noun:
        p.add_argument(
            f"--include-hidden-{noun}",
            action="store_true",
            help=f"Consider hidden {noun} as well",
        )
