"""Pure formatting of the ros2 verbs, no DDS: texts as Jazzy's ros2cli prints them.

Each expected text below follows what ros2cli's source prints for that shape:
rosidl_runtime_py's message_to_yaml (PyYAML block style of an ordered mapping,
width unbounded, sequences cut with a '...' item), `ros2 param describe`'s
lines, and `print()`'s trailing newline.
"""

from __future__ import annotations

import argparse

import pytest
from geometry_msgs.msg import Twist
from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    ParameterType,
)
from std_msgs.msg import Empty, String, UInt8MultiArray
from tutorial_interfaces.action import Fibonacci

from app.ros.context import CallContext
from app.ros2cli.common import is_hidden_name, visible, write_text
from app.ros2cli.msg_yaml import message_to_yaml
from app.ros2cli.param import describe_lines
from app.ros2cli.parser import UsageError, parse, run_argv
from app.ros2cli.topic import EchoStyle, bandwidth_text, echo_text, qos_fallback_lines


def test_sequences_print_in_block_style_not_indented_under_their_key():
    feedback = Fibonacci.Feedback(partial_sequence=[0, 1, 1, 2])
    assert message_to_yaml(feedback) == "partial_sequence:\n- 0\n- 1\n- 1\n- 2\n"
    assert message_to_yaml(Fibonacci.Result()) == "sequence: []\n"
    assert message_to_yaml(Fibonacci.Goal(order=5)) == "order: 5\n"


def test_nested_messages_floats_strings_and_empty_messages():
    twist = Twist()
    twist.linear.x = 2.0
    twist.angular.z = 1.8
    assert message_to_yaml(twist) == (
        "linear:\n  x: 2.0\n  y: 0.0\n  z: 0.0\nangular:\n  x: 0.0\n  y: 0.0\n  z: 1.8\n"
    )
    assert message_to_yaml(String(data="Hello World: 7")) == "data: 'Hello World: 7'\n"
    assert message_to_yaml(String(data="héllo")) == "data: héllo\n"  # unicode kept
    assert message_to_yaml(Empty()) == "{}\n"


def test_truncation_as_topic_echo_does():
    long = UInt8MultiArray(data=list(range(5)))
    text = message_to_yaml(long, truncate_length=3)
    assert text.endswith("data:\n- 0\n- 1\n- 2\n- '...'\n"), text
    assert message_to_yaml(String(data="abcdef"), truncate_length=3) == "data: abc...\n"
    # no line wrapping, however long the text
    assert message_to_yaml(String(data="x " * 200)).count("\n") == 1


def test_echo_text_ends_with_the_separator():
    assert echo_text(String(data="hi")) == "data: hi\n---"
    assert echo_text(2.0) == "2.0\n---"  # a selected primitive field, printed by Python


def test_param_describe_lines():
    turtlesim_b = ParameterDescriptor(
        name="background_b",
        type=ParameterType.PARAMETER_INTEGER,
        description="Blue channel of the background color",
        integer_range=[IntegerRange(from_value=0, to_value=255, step=1)],
    )
    assert describe_lines(turtlesim_b) == [
        "Parameter name: background_b",
        "  Type: integer",
        "  Description: Blue channel of the background color",
        "  Constraints:",
        "    Min value: 0",
        "    Max value: 255",
        "    Step: 1",
    ]
    rate = ParameterDescriptor(
        name="publish_rate_hz",
        type=ParameterType.PARAMETER_DOUBLE,
        read_only=True,
        floating_point_range=[FloatingPointRange(from_value=0.1, to_value=20.0)],
        additional_constraints="only on Tuesdays",
    )
    assert describe_lines(rate) == [
        "Parameter name: publish_rate_hz",
        "  Type: double",
        "  Constraints:",
        "    Read only: true",
        "    Min value: 0.1",
        "    Max value: 20.0",
        "    Additional constraints: only on Tuesdays",
    ]
    assert describe_lines(ParameterDescriptor(name="x")) == [
        "Parameter name: x",
        "  Type: not set",
        "  Constraints:",
    ]


def test_hidden_names():
    assert is_hidden_name("/turtlesim/_trails")
    assert is_hidden_name("/_ros2_classroom_cli_42/describe_parameters")
    assert is_hidden_name("/fibonacci/_action/send_goal")
    assert not is_hidden_name("/turtle1/cmd_vel")
    pairs = [("/a", ["t"]), ("/_b/c", ["t"])]
    assert visible(pairs) == [("/a", ["t"])]
    assert visible(pairs, include_hidden=True) == pairs


def test_write_text_shows_what_print_shows():
    lines: list[str] = []
    ctx = CallContext(node=None, write=lines.append)  # type: ignore[arg-type]
    write_text(ctx, "    " + message_to_yaml(Fibonacci.Feedback(partial_sequence=[0, 1])))
    # `print('Feedback:\n    {}'.format(yaml))`: only the first YAML line is indented,
    # and the YAML's own newline gives an empty line.
    assert lines == ["    partial_sequence:", "- 0", "- 1", ""]


def _help(argv: list[str]) -> list[str]:
    lines: list[str] = []
    assert parse(argv, lines.append) is None
    return lines


def test_help_names_upstream_options_and_what_is_not_supported():
    text = "\n".join(_help(["topic", "pub", "-h"]))
    for option in ("-r N, --rate N", "-p N, --print N", "-1, --once", "-t TIMES, --times TIMES"):
        assert option in text, text
    assert "--wait-matching-subscriptions" in text and "--max-wait-time-secs" in text
    assert "--keep-alive N" in text
    assert (
        "Not supported here (Jazzy's ros2 has them): --stdin, -n/--node-name, -s/--use-sim-time"
        in (" ".join(text.split()))
    )
    assert "--qos-reliability {system_default,reliable,best_effort,unknown,best_available}" in text
    # ...and listed as ros2 lists them, so -h reads as upstream's; typing one is refused
    assert "  --stdin               Read values from standard input" in text
    with pytest.raises(UsageError, match="argument --stdin: not supported here"):
        parse(["topic", "pub", "--stdin", "/x", "std_msgs/msg/String"], [].append)
    text = "\n".join(_help(["node", "info", "-h"]))
    assert "--include-hidden" in text
    text = "\n".join(_help(["param", "describe", "-h"]))
    assert "parameter_names" in text and "--include-hidden-nodes" in text
    for argv in (
        ["service", "list", "-h"],
        ["topic", "list", "-h"],
        ["topic", "echo", "-h"],
        ["action", "send_goal", "-h"],
        ["lifecycle", "set", "-h"],
    ):
        assert any(line.startswith("usage: ros2 ") for line in _help(argv)), argv


def test_abbreviated_include_hidden_is_accepted_as_ros2_accepts_it():
    args = parse(["topic", "list", "--include-hidden"], lambda _line: None)
    assert isinstance(args, argparse.Namespace) and args.include_hidden_topics
    args = parse(["service", "list", "--include-hidden"], lambda _line: None)
    assert isinstance(args, argparse.Namespace) and args.include_hidden_services
    # before the verb, as `ros2 topic --include-hidden-topics type ...` takes it
    args = parse(["topic", "--include-hidden-topics", "type", "/_x"], lambda _line: None)
    assert isinstance(args, argparse.Namespace) and args.include_hidden_topics
    args = parse(["service", "--include-hidden-services", "info", "/_x"], lambda _line: None)
    assert isinstance(args, argparse.Namespace) and args.include_hidden_services


def test_bandwidth_lines_use_one_unit_chosen_by_the_rate():
    assert bandwidth_text(500.0, 10, 50.0, 40, 60) == (
        "500 B/s from 10 messages\n\tMessage size mean: 50 B min: 40 B max: 60 B"
    )
    assert bandwidth_text(12_346.0, 100, 1236.0, 1000, 1500) == (
        "12.35 KB/s from 100 messages\n\tMessage size mean: 1.24 KB min: 1.00 KB max: 1.50 KB"
    )
    assert bandwidth_text(2_500_000.0, 100, 25_000.0, 25_000, 25_000) == (
        "2.50 MB/s from 100 messages\n\tMessage size mean: 0.03 MB min: 0.03 MB max: 0.03 MB"
    )


def test_interface_proto_prints_a_quoted_default_instance():
    lines: list[str] = []
    ctx = CallContext(node=None, write=lines.append)  # type: ignore[arg-type]
    assert run_argv(ctx, ["interface", "proto", "geometry_msgs/msg/Vector3"]) == 0
    assert lines == ['"x: 0.0', "y: 0.0", "z: 0.0", '"']
    lines.clear()
    assert (
        run_argv(ctx, ["interface", "proto", "tutorial_interfaces/action/Fibonacci", "--no-quotes"])
        == 0
    )
    assert lines == ["order: 0", ""]  # the goal, as print() shows YAML's last newline


def test_echo_options_no_arr_no_str_flow_style_and_csv():
    from geometry_msgs.msg import Point32, Polygon
    from sensor_msgs.msg import Imu

    msg = UInt8MultiArray(data=[1, 2, 3])
    assert echo_text(msg, EchoStyle(no_arr=True)).endswith(
        "data: '<sequence type: uint8, length: 3>'\n---"
    )
    imu = Imu()
    text = echo_text(imu, EchoStyle(no_arr=True, no_str=True))
    assert "  frame_id: '<string length: <0>>'" in text, text
    assert "orientation_covariance: '<array type: double[9]>'" in text, text
    assert echo_text(Polygon(), EchoStyle(no_arr=True)) == (
        "points: '<sequence type: geometry_msgs/msg/Point32, length: 0>'\n---"
    )
    # --flow-style: lists in flow style, messages (mappings) still in block style
    assert echo_text(String(data="hi"), EchoStyle(flow_style=True)) == "data: hi\n---"
    assert echo_text(Polygon(points=[Point32(x=1.0)]), EchoStyle(flow_style=True)) == (
        "points: [{x: 1.0, y: 0.0, z: 0.0}]\n---"
    )
    assert echo_text(UInt8MultiArray(data=[1, 2]), EchoStyle(flow_style=True)) == (
        "layout:\n  dim: []\n  data_offset: 0\ndata: [1, 2]\n---"
    )
    twist = Twist()
    twist.linear.x = 2.0
    assert echo_text(twist, EchoStyle(csv=True)) == "2.0,0.0,0.0,0.0,0.0,0.0"
    # layout: its empty dim adds nothing (not even a comma), data_offset 0; then the data
    assert echo_text(msg, EchoStyle(csv=True, truncate_length=2)) == "0,1,2,..."


def test_echo_says_when_it_falls_back_to_best_effort_or_volatile():
    from types import SimpleNamespace

    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    def publisher(reliability, durability):
        return SimpleNamespace(
            qos_profile=QoSProfile(depth=10, reliability=reliability, durability=durability)
        )

    reliable_latched = publisher(ReliabilityPolicy.RELIABLE, DurabilityPolicy.TRANSIENT_LOCAL)
    best_effort = publisher(ReliabilityPolicy.BEST_EFFORT, DurabilityPolicy.VOLATILE)
    assert qos_fallback_lines([reliable_latched, reliable_latched]) == []
    assert qos_fallback_lines([reliable_latched, best_effort]) == [
        "Some, but not all, publishers are offering QoSReliabilityPolicy.RELIABLE. Falling back "
        "to QoSReliabilityPolicy.BEST_EFFORT as it will connect to all publishers",
        "Some, but not all, publishers are offering QoSDurabilityPolicy.TRANSIENT_LOCAL. Falling "
        "back to QoSDurabilityPolicy.VOLATILE as it will connect to all publishers",
    ]


# What the real Jazzy `ros2` printed at 100 columns (bench/results/ros2cli_compare.md).
NODE_HELP = """\
usage: ros2 node [-h] Call `ros2 node <command> -h` for more detailed usage. ...

Various node related sub-commands

options:
  -h, --help            show this help message and exit

Commands:
  info  Output information about a node
  list  Output a list of available nodes

  Call `ros2 node <command> -h` for more detailed usage."""

HZ_HELP = """\
usage: ros2 topic hz [-h] [--window WINDOW] [--filter EXPR] [--wall-time] [--spin-time SPIN_TIME]
                     [-s]
                     topic_name

Print the average publishing rate to screen

positional arguments:
  topic_name            Name of the ROS topic to listen to (e.g. '/chatter')

options:
  -h, --help            show this help message and exit
  --window WINDOW, -w WINDOW
                        window size, in # of messages, for calculating rate (default: 10000)
  --filter EXPR         only measure messages matching the specified Python expression
  --wall-time           calculates rate using wall time which can be helpful when clock is not
                        published during simulation
  --spin-time SPIN_TIME
                        Spin time in seconds to wait for discovery (only applies when not using an
                        already running daemon)
  -s, --use-sim-time    Enable ROS simulation time"""


def test_help_is_ros2s_own_text(monkeypatch):
    monkeypatch.setenv("COLUMNS", "100")
    assert "\n".join(_help(["node", "-h"])) == NODE_HELP
    ours_only = (
        "",
        "Not supported here (Jazzy's ros2 has them): --filter, --wall-time, -s/--use-sim-time. "
        "Using one gives a usage error.",
    )
    assert _help(["topic", "hz", "-h"]) == [*HZ_HELP.split("\n"), *ours_only]
    # `ros2 node` alone: the same help, on the output, exit code 0 (as ros2cli)
    lines: list[str] = []
    args = parse(["node"], lines.append)
    assert args is not None
    assert args.handler(CallContext(None, lines.append), args) == 0  # type: ignore[arg-type]
    assert "\n".join(lines) == NODE_HELP
    # a verb ros2 has and we do not: a choice (ros2's list of choices), refused clearly
    with pytest.raises(UsageError, match="invalid choice: 'nope' .*'delay', 'echo'"):
        parse(["topic", "nope"], [].append)
    args = parse(["topic", "delay", "/x"], [].append)
    assert args is not None
    with pytest.raises(UsageError, match="`ros2 topic delay` is not supported here"):
        args.handler(CallContext(None, [].append), args)  # type: ignore[arg-type]


def test_qos_options_build_the_profile_as_ros2cli_does():
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, ReliabilityPolicy

    from app.ros2cli.topic import ECHO_QOS, PUB_QOS, QosOptions

    assert not ECHO_QOS.overridden() and not PUB_QOS.overridden()
    pub = PUB_QOS.profile_with_overrides()  # the 'default' preset: what `ros2 topic pub` uses
    assert (pub.reliability, pub.durability, pub.depth) == (
        ReliabilityPolicy.RELIABLE,
        DurabilityPolicy.VOLATILE,
        10,
    )
    qos = QosOptions("sensor_data", reliability="reliable", depth=3, history="keep_all")
    profile = qos.profile_with_overrides()
    assert qos.overridden()
    assert (profile.reliability, profile.depth, profile.history) == (
        ReliabilityPolicy.RELIABLE,
        3,
        HistoryPolicy.KEEP_ALL,
    )
    # transient local with no depth keeps the one last message
    latched = QosOptions("system_default", durability="transient_local", depth=0)
    assert latched.profile_with_overrides().depth == 1
    with pytest.raises(UsageError, match="argument --qos-profile: invalid choice: 'nope'"):
        parse(["topic", "echo", "--qos-profile", "nope", "/x"], [].append)
