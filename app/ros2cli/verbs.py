"""The arguments of `ros2 node/topic/service/action/param/lifecycle/interface` verbs.

Each verb takes the options of Jazzy's ros2cli, in its order, with its names,
metavars and help texts, so ``-h`` reads as the docs and the real tool show it
(compared side by side: bench/results/ros2cli_compare.md). The few options we
do not offer are still listed (the same ``-h``), named again at the end of the
help ("Not supported here"), and refused with argparse's usage error when
typed, never silently ignored.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import TYPE_CHECKING, TypedDict

from rclpy.qos import (
    QoSDurabilityPolicy,
    QoSHistoryPolicy,
    QoSLivelinessPolicy,
    QoSPresetProfiles,
    QoSReliabilityPolicy,
)

from app.ros2cli import graph_verbs, lifecycle, param, topic
from app.ros2cli.common import Commands, Verb

if TYPE_CHECKING:
    from typing_extensions import Unpack  # typing's own from Python 3.11

NOT_HERE = "not supported here"


class _NotHere(argparse.Action):
    """An option Jazzy's ros2 has and we do not: shown in -h, refused when used."""

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: object,
        option_string: str | None = None,
    ) -> None:
        raise argparse.ArgumentError(self, f"{NOT_HERE} (see the end of -h)")


class _NotHereOptions(TypedDict, total=False):
    help: str
    metavar: str
    dest: str


def not_here(
    p: argparse.ArgumentParser,
    *flags: str,
    flag: bool = False,
    group: argparse._MutuallyExclusiveGroup | None = None,
    **kw: Unpack[_NotHereOptions],
) -> None:
    """Add an option we do not offer (``flag``: it takes no value), and name it in the epilog.

    ``group``: the mutually exclusive group it belongs to (else the parser itself).
    """
    target = p if group is None else group
    target.add_argument(*flags, action=_NotHere, nargs=0 if flag else None, **kw)
    names: list[str] = p.__dict__.setdefault("_not_here", [])
    names.append("/".join(sorted(flags, key=len)))
    p.epilog = (
        f"Not supported here (Jazzy's ros2 has them): {', '.join(names)}. "
        "Using one gives a usage error."
    )


def positive_float(text: str) -> float:
    """ros2topic's float > 0 (argparse names this function in its error)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError("Expects a floating point number") from None
    if value <= 0.0:
        raise argparse.ArgumentTypeError("Value must be positive")
    return value


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value <= 0:
        raise argparse.ArgumentTypeError("value must be a positive integer")
    return value


def unsigned_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError("value must be non-negative integer")
    return value


def nonnegative_int(text: str) -> int:
    value = int(text)
    if value < 0:
        raise ValueError("Value must be positive or zero")
    return value


def spin_time(p: argparse.ArgumentParser) -> None:
    """--spin-time and -s: the options of ros2cli's own (direct) node."""
    p.add_argument(
        "--spin-time",
        type=float,
        default=None,
        help="Spin time in seconds to wait for discovery (only applies when not using an "
        "already running daemon)",
    )
    not_here(p, "-s", "--use-sim-time", flag=True, help="Enable ROS simulation time")


def strategy(p: argparse.ArgumentParser) -> None:
    """--spin-time, -s, --no-daemon (there is no daemon here: never spawned nor used)."""
    spin_time(p)
    p.add_argument(
        "--no-daemon",
        action="store_true",
        help="Do not spawn nor use an already running daemon",
    )


def qos_options(p: argparse.ArgumentParser, verb: str, default_profile: str) -> None:
    """`topic echo` and `topic pub`'s QoS options (read back by ``qos_of``)."""
    history = QoSPresetProfiles.get_from_short_key(default_profile).history.short_key
    compatible = "default: Compatible profile with running endpoints )"
    p.add_argument(
        "--qos-profile",
        choices=QoSPresetProfiles.short_keys(),
        default=default_profile,
        help=f"Quality of service preset profile to {verb} with (default: {default_profile})",
    )
    p.add_argument(
        "--qos-depth",
        metavar="N",
        type=int,
        help=f"Queue size setting to {verb} with (overrides depth value of --qos-profile option)",
    )
    p.add_argument(
        "--qos-history",
        choices=QoSHistoryPolicy.short_keys(),
        help=f"History of samples setting to {verb} with (overrides history value of "
        f"--qos-profile option, default: {history})",
    )
    p.add_argument(
        "--qos-reliability",
        choices=QoSReliabilityPolicy.short_keys(),
        help=f"Quality of service reliability setting to {verb} with (overrides "
        f"reliability value of --qos-profile option, {compatible}",
    )
    p.add_argument(
        "--qos-durability",
        choices=QoSDurabilityPolicy.short_keys(),
        help=f"Quality of service durability setting to {verb} with (overrides "
        f"durability value of --qos-profile option, {compatible}",
    )
    p.add_argument(
        "--qos-liveliness",
        choices=QoSLivelinessPolicy.short_keys(),
        help=f"Quality of service liveliness setting to {verb} with (overrides "
        "liveliness value of --qos-profile option",
    )
    p.add_argument(
        "--qos-liveliness-lease-duration-seconds",
        type=float,
        help=f"Quality of service liveliness lease duration setting to {verb} with "
        "(overrides liveliness lease duration value of --qos-profile option",
    )


def qos_of(a: argparse.Namespace) -> topic.QosOptions:
    return topic.QosOptions(
        a.qos_profile,
        reliability=a.qos_reliability,
        durability=a.qos_durability,
        depth=a.qos_depth,
        history=a.qos_history,
        liveliness=a.qos_liveliness,
        lease_seconds=a.qos_liveliness_lease_duration_seconds,
    )


def _node_listing_options(p: argparse.ArgumentParser) -> None:
    """`ros2 node list` and `ros2 lifecycle nodes` take the same options."""
    strategy(p)
    p.add_argument("-a", "--all", action="store_true", help="Display all nodes even hidden ones")
    p.add_argument(
        "-c",
        "--count-nodes",
        action="store_true",
        help="Only display the number of nodes discovered",
    )


def add_node(v: Commands, verb: Verb) -> None:
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


HIDDEN_TOPICS_HELP = "Consider hidden topics as well"


def add_topic(v: Commands, verb: Verb) -> None:
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
    p.add_argument("--include-hidden-topics", action="store_true", help=HIDDEN_TOPICS_HELP)
    p.add_argument(
        "-v", "--verbose", action="store_true", help="List full details about each topic"
    )

    p = verb(
        v,
        "info",
        "Print information about a topic",
        lambda c, a: topic.topic_info(c, a.topic_name, a.verbose),
    )
    strategy(p)
    p.add_argument("topic_name", help="Name of the ROS topic to get info (e.g. '/chatter')")
    p.add_argument(
        "--verbose",
        "-v",
        action="store_true",
        help="Prints detailed information like the node name, node namespace, topic type, "
        "topic type hash, GUID, and QoS Profile of the publishers and subscribers to this topic",
    )

    p = verb(
        v,
        "type",
        "Print a topic's type",
        lambda c, a: topic.topic_type(c, a.topic_name, a.include_hidden_topics),
    )
    strategy(p)
    p.add_argument("topic_name", help="Name of the ROS topic to get type (e.g. '/chatter')")

    p = verb(
        v,
        "find",
        "Output a list of available topics of a given type",
        lambda c, a: topic.find(c, a.topic_type, a.count_topics, a.include_hidden_topics),
    )
    strategy(p)
    # (sic: ros2cli's example says std_msg)
    p.add_argument(
        "topic_type", help="Name of the ROS topic type to filter for (e.g. 'std_msg/msg/String')"
    )
    p.add_argument(
        "-c",
        "--count-topics",
        action="store_true",
        help="Only display the number of topics discovered",
    )
    p.add_argument("--include-hidden-topics", action="store_true", help=HIDDEN_TOPICS_HELP)

    _add_echo(v, verb)

    p = verb(
        v,
        "hz",
        "Print the average publishing rate to screen",
        lambda c, a: topic.hz(c, a.topic_name, None, a.window_size),
    )
    p.add_argument("topic_name", help="Name of the ROS topic to listen to (e.g. '/chatter')")
    p.add_argument(
        "--window",
        "-w",
        dest="window_size",
        type=positive_int,
        default=10_000,
        metavar="WINDOW",
        help="window size, in # of messages, for calculating rate (default: 10000)",
    )
    not_here(
        p, "--filter", metavar="EXPR", help="only measure messages matching the specified "
        "Python expression",
    )  # fmt: skip
    not_here(
        p,
        "--wall-time",
        flag=True,
        help="calculates rate using wall time which can be helpful when clock is not "
        "published during simulation",
    )
    spin_time(p)

    p = verb(
        v,
        "bw",
        "Display bandwidth used by topic",
        lambda c, a: topic.bw(c, a.topic, None, a.window),
    )
    p.add_argument("topic", help="Topic name to monitor for bandwidth utilization")
    p.add_argument(
        "--window",
        "-w",
        type=positive_int,
        default=100,
        metavar="WINDOW",
        help="maximum window size, in # of messages, for calculating rate (default: 100)",
    )
    spin_time(p)

    _add_pub(v, verb)


def _add_echo(v: Commands, verb: Verb) -> None:
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
            qos=qos_of(a),
        ),
    )
    strategy(p)
    p.add_argument("topic_name", help="Name of the ROS topic to listen to (e.g. '/chatter')")
    p.add_argument(
        "message_type", nargs="?", help="Type of the ROS message (e.g. 'std_msgs/msg/String')"
    )
    qos_options(p, "subscribe", "sensor_data")
    p.add_argument(
        "--csv",
        action="store_true",
        help="Output all recursive fields separated by commas (e.g. for plotting). If "
        "--include-message-info is also passed, the following fields are prepended: "
        "source_timestamp, received_timestamp, publication_sequence_number, "
        "reception_sequence_number.",
    )
    p.add_argument(
        "--field",
        type=str,
        default=None,
        help="Echo a selected field of a message. Use '.' to select sub-fields. For example, "
        "to echo the position field of a nav_msgs/msg/Odometry message: "
        "'ros2 topic echo /odom --field pose.pose.position'",
    )
    p.add_argument(
        "--full-length",
        "-f",
        action="store_true",
        help="Output all elements for arrays, bytes, and string with a length > "
        "'--truncate-length', by default they are truncated after '--truncate-length' "
        "elements with '...''",
    )
    p.add_argument(
        "--truncate-length",
        "-l",
        type=unsigned_int,
        default=128,
        help="The length to truncate arrays, bytes, and string to (default: 128)",
    )
    p.add_argument("--no-arr", action="store_true", help="Don't print array fields of messages")
    p.add_argument("--no-str", action="store_true", help="Don't print string fields of messages")
    # (sic: ros2cli's help says block style for the option that asks for the flow style)
    p.add_argument(
        "--flow-style",
        action="store_true",
        help="Print collections in the block style (not available with csv format)",
    )
    not_here(p, "--no-lost-messages", flag=True, help="Don't report when a message is lost")
    not_here(p, "--raw", flag=True, help="Echo the raw binary representation")
    not_here(
        p,
        "--filter",
        dest="filter_expr",
        help="Python expression to filter messages that are printed. Expression can use "
        "Python builtins as well as m (the message).",
    )
    p.add_argument(
        "--once", action="store_true", help="Print the first message received and then exit."
    )
    p.add_argument(
        "--timeout",
        metavar="N",
        type=positive_float,
        default=None,
        help="Set a timeout in seconds for waiting",
    )
    not_here(
        p, "--include-message-info", "-i", flag=True, help="Shows the associated message info."
    )


def _add_pub(v: Commands, verb: Verb) -> None:
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
            qos=qos_of(a),
        ),
    )
    p.add_argument("topic_name", help="Name of the ROS topic to publish to (e.g. '/chatter')")
    p.add_argument("message_type", help="Type of the ROS message (e.g. 'std_msgs/String')")
    values_or_stdin = p.add_mutually_exclusive_group()
    values_or_stdin.add_argument(
        "values",
        nargs="?",
        default="{}",
        help="Values to fill the message with in YAML format (e.g. 'data: Hello World'), "
        "otherwise the message will be published with default values",
    )
    not_here(p, "--stdin", flag=True, group=values_or_stdin, help="Read values from standard input")
    p.add_argument(
        "-r",
        "--rate",
        metavar="N",
        type=positive_float,
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
        "-t",
        "--times",
        type=nonnegative_int,
        default=0,
        help="Publish this number of times and then exit",
    )
    p.add_argument(
        "-w",
        "--wait-matching-subscriptions",
        type=nonnegative_int,
        default=None,
        help="Wait until finding the specified number of matching subscriptions. "
        'Defaults to 1 when using "-1"/"--once"/"--times", otherwise defaults to 0.',
    )
    p.add_argument(
        "--max-wait-time-secs",
        type=positive_float,
        default=None,
        help="This sets the maximum wait time in seconds if "
        "--wait-until-matching-subscriptions is set. By default, this flag is not set "
        "meaning the subscriber will wait endlessly.",
    )
    p.add_argument(
        "--keep-alive",
        metavar="N",
        type=positive_float,
        default=0.1,
        help="Keep publishing node alive for N seconds after the last msg (default: 0.1)",
    )
    not_here(p, "-n", "--node-name", help="Name of the created publishing node")
    qos_options(p, "publish", "default")
    spin_time(p)


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


def add_service(v: Commands, verb: Verb) -> None:
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
    _count_services(p)

    p = verb(
        v,
        "type",
        "Output a service's type",
        lambda c, a: graph_verbs.service_type(c, a.service_name, a.include_hidden_services),
    )
    p.add_argument(
        "service_name",
        help="Name of the ROS service to get type (e.g. '/talker/list_parameters')",
    )

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
    _count_services(p)

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


def add_action(v: Commands, verb: Verb) -> None:
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
    # (sic: "a action's", and the example of `action type` says "get info")
    p = verb(
        v, "type", "Print a action's type", lambda c, a: graph_verbs.action_type(c, a.action_name)
    )
    p.add_argument("action_name", help="Name of the ROS action to get info (e.g. '/fibonacci')")
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


def _node_name(p: argparse.ArgumentParser, optional: bool = False, help_text: str = "") -> None:
    p.add_argument(
        "node_name", nargs="?" if optional else None, help=help_text or "Name of the ROS node"
    )


def _hidden_nodes(p: argparse.ArgumentParser) -> None:
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


def add_param(v: Commands, verb: Verb) -> None:
    p = verb(
        v,
        "list",
        "Output a list of available parameters",
        lambda c, a: param.param_list(
            c,
            a.node_name,
            a.param_type,
            a.include_hidden_nodes,
            a.param_prefixes,
            a.filter[0] if a.filter else None,
        ),
    )
    strategy(p)
    _node_name(p, optional=True)
    p.add_argument(
        "--filter",
        nargs=1,
        help="Only parameters matching the regex expression will be showed. "
        "Supports `re` regex syntax.",
    )
    _hidden_nodes(p)
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
        lambda c, a: param.param_get(
            c, a.node_name, a.parameter_name, a.include_hidden_nodes, a.hide_type
        ),
    )
    strategy(p)
    _node_name(p)
    _hidden_nodes(p)
    p.add_argument("parameter_name", help="Name of the parameter")
    p.add_argument("--hide-type", action="store_true", help="Hide the type information")
    _timeout(p)

    p = verb(
        v,
        "set",
        "Set parameter",
        lambda c, a: param.param_set(
            c, a.node_name, a.parameter_name, a.value, a.include_hidden_nodes
        ),
    )
    strategy(p)
    _node_name(p)
    _hidden_nodes(p)
    p.add_argument("parameter_name", help="Name of the parameter")
    p.add_argument("value", help="Value of the parameter")
    _timeout(p)

    p = verb(
        v,
        "describe",
        "Show descriptive information about declared parameters",
        lambda c, a: param.param_describe(
            c, a.node_name, a.parameter_names, a.include_hidden_nodes
        ),
    )
    strategy(p)
    _node_name(p)
    _hidden_nodes(p)
    p.add_argument("parameter_names", nargs="+", help="Names of the parameters")
    _timeout(p)

    p = verb(
        v,
        "dump",
        "Show all of the parameters of a node in a YAML file format",
        lambda c, a: param.param_dump(c, a.node_name, a.include_hidden_nodes),
    )
    strategy(p)
    _node_name(p)
    _hidden_nodes(p)
    _timeout(p)

    p = verb(
        v,
        "load",
        "Load parameter file for a node",
        lambda c, a: param.param_load(
            c, a.node_name, a.parameter_file, a.include_hidden_nodes, not a.no_use_wildcard
        ),
    )
    strategy(p)
    _node_name(p)
    _hidden_nodes(p)
    p.add_argument("parameter_file", help="Parameter file")
    p.add_argument(
        "--no-use-wildcard",
        action="store_true",
        help="Do not load parameters in the '/**' namespace into the node",
    )
    _timeout(p)

    p = verb(
        v,
        "delete",
        "Delete parameter",
        lambda c, a: param.param_delete(c, a.node_name, a.parameter_name, a.include_hidden_nodes),
    )
    strategy(p)
    _node_name(p)
    _hidden_nodes(p)
    p.add_argument("parameter_name", help="Name of the parameter")
    _timeout(p)


def add_lifecycle(v: Commands, verb: Verb) -> None:
    p = verb(
        v,
        "get",
        "Get lifecycle state for one or more nodes",
        lambda c, a: lifecycle.verb_get(c, a.node_name, a.include_hidden_nodes),
    )
    strategy(p)
    _node_name(
        p,
        optional=True,
        help_text="Name of the ROS node. If no name is provided, then get the state for all nodes.",
    )
    _hidden_nodes(p)

    p = verb(
        v,
        "list",
        "Output a list of available transitions",
        lambda c, a: lifecycle.verb_list(c, a.node_name, a.include_hidden_nodes, a.all),
    )
    strategy(p)
    _node_name(p)
    _hidden_nodes(p)
    p.add_argument("-a", "--all", action="store_true", help="Display all existing transitions")

    p = verb(
        v,
        "nodes",
        "Output a list of nodes with lifecycle",
        lambda c, a: lifecycle.verb_nodes(c, a.count_nodes, a.all),
    )
    _node_listing_options(p)

    p = verb(
        v,
        "set",
        "Trigger lifecycle state transition",
        lambda c, a: lifecycle.verb_set(c, a.node_name, a.transition, a.include_hidden_nodes),
    )
    strategy(p)
    _node_name(p)
    _hidden_nodes(p)
    p.add_argument("transition", help="The lifecycle transition")


def only_kinds(p: argparse.ArgumentParser, what: Sequence[str] | None = None) -> None:
    """`ros2 interface list/package(s)`: -m, -s, -a, with each verb's own help texts."""
    texts = what or (
        "Print out only the message types",
        "Print out only the service types",
        "Print out only the action types",
    )
    for short, long, text in zip(
        ("-m", "-s", "-a"), ("--only-msgs", "--only-srvs", "--only-actions"), texts, strict=True
    ):
        p.add_argument(short, long, action="store_true", help=text)


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
