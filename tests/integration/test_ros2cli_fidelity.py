"""Golden outputs: each verb prints what Jazzy's ros2cli prints, against our real nodes.

The expected texts are written out in full, from what ros2cli's source prints
for each shape (`print(*[], sep='\\n')` gives the empty line of an empty
section; `print('Feedback:\\n    {}'.format(message_to_yaml(...)))` indents only
the first YAML line; rclpy's TopicEndpointInfo text for `topic info -v`; and
so on). Only goal ids and GIDs are normalised. Both faces are run: the
Console's (run_text on the probe node) and the terminal's (`python -m app`,
which creates the hidden node /_ros2_classroom_cli_<pid>).
"""

from __future__ import annotations

import re

import pytest
from rclpy.node import Node

from app.ros.context import CallContext, Limits
from app.ros2cli import run_text
from tests.conftest import run_cli
from tests.integration.conftest import TEST_LIMITS, Ros2Runner

pytestmark = pytest.mark.ros

PARAM_SERVICES = [
    "describe_parameters: rcl_interfaces/srv/DescribeParameters",
    "get_parameter_types: rcl_interfaces/srv/GetParameterTypes",
    "get_parameters: rcl_interfaces/srv/GetParameters",
    "get_type_description: type_description_interfaces/srv/GetTypeDescription",
    "list_parameters: rcl_interfaces/srv/ListParameters",
    "set_parameters: rcl_interfaces/srv/SetParameters",
    "set_parameters_atomically: rcl_interfaces/srv/SetParametersAtomically",
]
STANDARD_PUBLISHERS = [
    "    /parameter_events: rcl_interfaces/msg/ParameterEvent",
    "    /rosout: rcl_interfaces/msg/Log",
]
# std_msgs/msg/String's type hash in Jazzy (RIHS01: SHA-256 of its type description)
STRING_HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"


class ExactRunner(Ros2Runner):
    """Keeps every line as written, trailing empty lines too (print()'s last newline)."""

    def __call__(self, text: str, limits: Limits | None = None) -> tuple[int, list[str]]:
        written: list[str] = []
        code = run_text(CallContext(self.node, written.append, limits or TEST_LIMITS), text)
        return code, [part for line in written for part in line.split("\n")]


@pytest.fixture
def ros2(probe) -> ExactRunner:
    return ExactRunner(probe.node)


def servers_of(node: str) -> list[str]:
    return [f"    /{node}/{line}" for line in PARAM_SERVICES]


def normalised(lines: list[str]) -> list[str]:
    out = []
    for line in lines:
        line = re.sub(r"^GID: [0-9a-f.]+$", "GID: <gid>", line)
        line = re.sub(r"^Goal accepted with ID: [0-9a-f]{32}$", "Goal accepted with ID: <id>", line)
        out.append(line)
    return out


def talker_info() -> list[str]:
    return [
        "/talker",
        "  Subscribers:",
        "",
        "  Publishers:",
        "    /chatter: std_msgs/msg/String",
        *STANDARD_PUBLISHERS,
        "  Service Servers:",
        *servers_of("talker"),
        "  Service Clients:",
        "",
        "  Action Servers:",
        "",
        "  Action Clients:",
        "",
    ]


def test_graph_verbs_golden(supervisor, ros2):
    for name in ("talker", "listener", "add_two_ints_server", "fibonacci_action_server"):
        supervisor.start(name)
    # endpoints and node names are discovered separately: wait for both
    ros2.until(
        "node list",
        lambda o: all(
            f"/{n}" in o.split("\n")
            for n in ("talker", "listener", "add_two_ints_server", "fibonacci_action_server")
        ),
    )
    ros2.until("node info /fibonacci_action_server", "/fibonacci: tutorial_interfaces")
    ros2.until("topic info /chatter", "Subscription count: 1")

    # node info: an empty section prints one empty line, the last one too
    assert ros2.until("node info /talker", lambda o: o.split("\n") == talker_info())
    assert ros2("node info /listener") == (
        0,
        [
            "/listener",
            "  Subscribers:",
            "    /chatter: std_msgs/msg/String",
            "  Publishers:",
            *STANDARD_PUBLISHERS,
            "  Service Servers:",
            *servers_of("listener"),
            "  Service Clients:",
            "",
            "  Action Servers:",
            "",
            "  Action Clients:",
            "",
        ],
    )
    code, lines = ros2("node info /fibonacci_action_server")
    assert lines[lines.index("  Action Servers:") :] == [
        "  Action Servers:",
        "    /fibonacci: tutorial_interfaces/action/Fibonacci",
        "  Action Clients:",
        "",
    ], lines
    assert not any("/_action/" in line for line in lines), lines  # hidden
    code, lines = ros2("node info /fibonacci_action_server --include-hidden")
    assert (
        "    /fibonacci/_action/send_goal: tutorial_interfaces/action/Fibonacci_SendGoal" in lines
    )

    # topic info, plain and verbose (rclpy's endpoint text, with the type hash)
    assert ros2("topic info /chatter") == (
        0,
        ["Type: std_msgs/msg/String", "Publisher count: 1", "Subscription count: 1"],
    )
    code, lines = ros2("topic info -v /chatter")
    endpoint = [
        "Topic type: std_msgs/msg/String",
        f"Topic type hash: {STRING_HASH}",
    ]
    qos = [
        "QoS profile:",
        "  Reliability: RELIABLE",
        "  History (Depth): UNKNOWN",
        "  Durability: VOLATILE",
        "  Lifespan: Infinite",
        "  Deadline: Infinite",
        "  Liveliness: AUTOMATIC",
        "  Liveliness lease duration: Infinite",
    ]
    assert normalised(lines) == [
        "Type: std_msgs/msg/String",
        "",
        "Publisher count: 1",
        "",
        "Node name: talker",
        "Node namespace: /",
        *endpoint,
        "Endpoint type: PUBLISHER",
        "GID: <gid>",
        *qos,
        "",
        "Subscription count: 1",
        "",
        "Node name: listener",
        "Node namespace: /",
        *endpoint,
        "Endpoint type: SUBSCRIPTION",
        "GID: <gid>",
        *qos,
        "",
    ], lines
    assert ros2("topic type /chatter") == (0, ["std_msgs/msg/String"])
    assert ros2("topic find std_msgs/msg/String") == (0, ["/chatter"])
    assert ros2("topic find -c std_msgs/msg/String") == (0, ["1"])
    code, lines = ros2("topic list -v")
    assert (
        lines[0] == "Published topics:" and " * /chatter [std_msgs/msg/String] 1 publisher" in lines
    )
    sub = lines.index("Subscribed topics:")
    assert lines[sub - 1] == "" and lines[-1] == "", lines
    assert " * /chatter [std_msgs/msg/String] 1 subscriber" in lines[sub:], lines

    # service call: ros2cli's reprs and empty lines; "waiting ..." only while the new
    # client has not matched the server yet (it may have, or not: ros2 alike)
    code, lines = ros2(
        "service call /add_two_ints tutorial_interfaces/srv/AddTwoInts '{a: 2, b: 3}'"
    )
    waiting = "waiting for service to become available..."
    assert (code, lines[1:] if lines[0] == waiting else lines) == (
        0,
        [
            "requester: making request: tutorial_interfaces.srv.AddTwoInts_Request(a=2, b=3)",
            "",
            "response:",
            "tutorial_interfaces.srv.AddTwoInts_Response(sum=5)",
            "",
        ],
    )
    # no server: the waiting line, and no request is printed before one is there
    assert ros2(
        "service call /nobody std_srvs/srv/Empty", Limits(service_timeout=1.0, max_seconds=2.0)
    ) == (1, [waiting, "error: service '/nobody' is not available (waited 1 s)"])
    code, lines = ros2("service call '{a: 1}' tutorial_interfaces/srv/AddTwoInts")
    assert code == 1 and len(lines) == 1, lines  # one line, no traceback
    assert lines[0].startswith("error: Invalid service name: "), lines
    assert ros2("service info /add_two_ints") == (
        0,
        ["Type: tutorial_interfaces/srv/AddTwoInts", "Clients count: 0", "Services count: 1"],
    )

    # action send_goal --feedback: block-style YAML lists; each line when its event is
    # handled, so the first feedback may come before "Goal accepted" (with ros2 too, when
    # rclpy handles it together with the acceptance)
    code, lines = ros2(
        "action send_goal /fibonacci tutorial_interfaces/action/Fibonacci '{order: 3}' --feedback"
    )
    lines = normalised(lines)
    accepted = lines.index("Goal accepted with ID: <id>")
    assert lines[accepted + 1] == "" and accepted in (4, 9), lines
    assert (code, lines[:accepted] + lines[accepted + 2 :]) == (
        0,
        [
            "Waiting for an action server to become available...",
            "Sending goal:",
            "     order: 3",
            "",
            "Feedback:",
            "    partial_sequence:",
            "- 0",
            "- 1",
            "",
            "Feedback:",
            "    partial_sequence:",
            "- 0",
            "- 1",
            "- 1",
            "",
            "Feedback:",
            "    partial_sequence:",
            "- 0",
            "- 1",
            "- 1",
            "- 2",
            "",
            "Result:",
            "    sequence:",
            "- 0",
            "- 1",
            "- 1",
            "- 2",
            "",
            "Goal finished with status: SUCCEEDED",
        ],
    ), lines
    # no server: the goal is not printed (ros2 would wait endlessly; we stop after the limit)
    assert ros2(
        "action send_goal /nobody tutorial_interfaces/action/Fibonacci '{order: 1}'",
        Limits(service_timeout=1.0, max_seconds=2.0),
    ) == (
        1,
        [
            "Waiting for an action server to become available...",
            "error: action server '/nobody' is not available (waited 1 s)",
        ],
    )
    assert ros2("action info /fibonacci -t") == (
        0,
        [
            "Action: /fibonacci",
            "Action clients: 0",
            "Action servers: 1",
            "    /fibonacci_action_server [tutorial_interfaces/action/Fibonacci]",
        ],
    )
    assert ros2("action info fibonacci") == (  # relative: expanded from our node, as ros2cli
        0,
        [
            "Action: fibonacci",
            "Action clients: 0",
            "Action servers: 1",
            "    /fibonacci_action_server",
        ],
    )
    code, lines = ros2("action info 'bad name!'")
    assert code == 1 and lines[0].startswith("topic name 'bad name!' is invalid"), lines
    assert ros2("action info /fibonacci -c") == (
        0,
        ["Action: /fibonacci", "Action clients: 0", "Action servers: 1"],
    )

    # topic pub: "Waiting for ..." only while too few subscriptions match
    assert ros2("topic pub --once /chatter std_msgs/msg/String '{data: hi}'") == (
        0,
        ["publisher: beginning loop", "publishing #1: std_msgs.msg.String(data='hi')", ""],
    )
    assert ros2("topic pub -w 2 --max-wait-time-secs 0.5 -t 1 /chatter std_msgs/msg/String") == (
        1,
        [
            "Waiting for at least 2 matching subscription(s)...",
            "Timed out waiting for subscribers: Expected 2 subcribers but only got 1 subscribers",
        ],
    )
    assert ros2("topic pub -t 4 -p 2 -r 20 /counted std_msgs/msg/Int32 '{data: 7}' -w 0") == (
        0,
        [
            "publisher: beginning loop",
            "publishing #2: std_msgs.msg.Int32(data=7)",
            "",
            "publishing #4: std_msgs.msg.Int32(data=7)",
            "",
        ],
    )

    # ros2cli's words and exit codes for what is not there
    assert ros2("node info /nobody") == (1, ["Unable to find node '/nobody'"])
    assert ros2("node info talker") == (1, ["Unable to find node 'talker'"])  # as typed
    assert ros2("topic info /nope") == (1, ["Unknown topic '/nope'"])
    # ros2 prints nothing for these (exit 1); the Console says why in parentheses
    assert ros2("topic type /nope") == (1, ["(no topic '/nope' on the graph)"])
    assert ros2("service type /nope") == (1, ["(no service '/nope' on the graph)"])
    assert ros2("service info /nope") == (1, ["Unknown service '/nope'"])
    assert ros2("action type /nope") == (1, ["(no action '/nope' on the graph)"])
    code, lines = ros2("node info")
    assert code == 2 and lines[0].startswith("usage: ros2 node info"), lines
    assert lines[-1] == "ros2 node info: error: the following arguments are required: node_name"
    code, lines = ros2("topic list --qos-profile sensor_data")
    assert code == 2
    # argparse reports unknown options from the root parser, in ros2 as here
    assert lines[-1] == "ros2: error: unrecognized arguments: --qos-profile sensor_data"


def test_param_lifecycle_and_hidden_names_golden(supervisor, probe, ros2):
    for name in ("turtlesim_node", "lifecycle_talker", "parameters_node"):
        supervisor.start(name)
    ros2.until("lifecycle nodes", "/lifecycle_talker")
    ros2.until("param list /parameters_node", "  greeting")

    # hidden topics stay hidden unless asked for (--include-hidden abbreviates as in ros2)
    # discovery brings a node's readers and writers separately: wait for both ends
    out = ros2.until(
        "node info /turtlesim",
        lambda o: (
            "/turtle1/pose: turtlesim/msg/Pose" in o
            and "/turtle1/cmd_vel: geometry_msgs/msg/Twist" in o
        ),
    )
    assert "_trails" not in out and "/_action/" not in out, out
    assert out.splitlines()[1:4] == [
        "  Subscribers:",
        "    /turtle1/cmd_vel: geometry_msgs/msg/Twist",
        "  Publishers:",
    ], out
    ros2.until(
        "node info /turtlesim --include-hidden",
        "    /turtlesim/_trails_request: std_msgs/msg/Empty",
    )
    code, lines = ros2("topic list")
    assert "/turtle1/pose" in lines and not any("/_" in line for line in lines), lines
    code, lines = ros2("topic list --include-hidden")
    assert {"/turtlesim/_trails", "/turtle1/rotate_absolute/_action/status"} <= set(lines)
    code, lines = ros2("service list")
    assert "/spawn" in lines and not any("/_" in line for line in lines), lines
    code, lines = ros2("service list --include-hidden-services")
    assert "/turtle1/rotate_absolute/_action/send_goal" in lines, lines

    # param describe: name, type, description, constraints
    assert ros2("param describe /turtlesim background_b holonomic") == (
        0,
        [
            "Parameter name: background_b",
            "  Type: integer",
            "  Description: Blue channel of the background color",
            "  Constraints:",
            "    Min value: 0",
            "    Max value: 255",
            "    Step: 1",
            "Parameter name: holonomic",
            "  Type: boolean",
            "  Description: If true, then turtles will be holonomic",
            "  Constraints:",
        ],
    )
    assert ros2("param describe /parameters_node publish_rate_hz") == (
        0,
        [
            "Parameter name: publish_rate_hz",
            "  Type: double",
            "  Description: messages per second",
            "  Constraints:",
            "    Min value: 0.1",
            "    Max value: 20.0",
        ],
    )
    assert ros2("param list /parameters_node --param-type --filter 'gr|sh'") == (
        0,
        ["  greeting (type: string)", "  shout (type: boolean)"],
    )
    assert ros2("param get /parameters_node greeting --hide-type") == (0, ["Hello"])
    assert ros2("param get /turtlesim background_b") == (0, ["Integer value is: 255"])
    assert ros2("param get /nobody greeting") == (1, ["Node not found"])
    silent = Node("no_params_here", context=probe.context, start_parameter_services=False)
    try:
        ros2.until("node list", "/no_params_here")
        assert ros2("param get /no_params_here x", Limits(service_timeout=1.0)) == (
            1,
            ["Wait for service timed out waiting for parameter services for node /no_params_here"],
        )
    finally:
        silent.destroy_node()

    # two nodes with one name: ros2cli's warnings (stderr in a terminal)
    twins = [Node("twin", context=probe.context) for _ in range(2)]
    try:
        out = ros2.until("node list", lambda o: o.split("\n").count("/twin") == 2)
        assert out.split("\n")[0] == (
            "WARNING: Be aware that there are nodes in the graph that share an exact name, "
            "which can have unintended side effects."
        ), out
        code, lines = ros2("node info /twin")
        assert lines[:2] == [
            'There are 2 nodes in the graph with the exact name "/twin". '
            "You are seeing information about only one of them.",
            "/twin",
        ], lines
    finally:
        for twin in twins:
            twin.destroy_node()
    assert ros2("param describe /nobody greeting") == (1, ["Node not found"])
    # the node refuses (rclpy's reason); ros2cli still exits with 0
    assert ros2("param delete /parameters_node shout") == (
        0,
        ["Deleting parameter failed: Static parameter cannot be undeclared"],
    )
    code, lines = ros2("param dump /parameters_node")
    assert lines[:3] == ["/parameters_node:", "  ros__parameters:", "    greeting: Hello"]
    assert lines[-1] == "", lines  # print() of yaml.dump's text

    # lifecycle: ros2cli's words for an unknown transition, exit code 0 after a try
    assert ros2("lifecycle get /lifecycle_talker") == (0, ["unconfigured [1]"])
    assert ros2("lifecycle set /lifecycle_talker frobnicate") == (
        1,
        ["Unknown transition requested, available ones are:", "- configure [1]", "- shutdown [5]"],
    )
    code, lines = ros2("lifecycle list /lifecycle_talker --all")
    assert code == 0 and "- activate [3]" in lines and "\tStart: inactive" in lines, lines
    assert ros2("lifecycle nodes -c") == (0, ["1"])
    assert ros2("lifecycle get /nobody") == (1, ["Node not found"])


def test_terminal_face_hides_its_own_node(ros_env, supervisor):
    supervisor.start("talker")
    # A fresh process discovers the graph as it goes: allow a second look when busy.
    for _attempt in range(3):
        done = run_cli("service", "list", "-t", env=ros_env)
        if "/talker/get_parameters [rcl_interfaces/srv/GetParameters]" in done.stdout:
            break
    assert done.returncode == 0, done.stderr
    assert "/talker/get_parameters [rcl_interfaces/srv/GetParameters]" in done.stdout
    assert "/_" not in done.stdout, done.stdout  # our CLI's own hidden node's services
    done = run_cli("service", "list", "--include-hidden-services", env=ros_env)
    # like ros2cli's own node: a type description service, no parameter services
    own = re.findall(r"^/_ros2_classroom_cli_\d+/\w+$", done.stdout, re.MULTILINE)
    assert own and all(name.endswith("/get_type_description") for name in own), done.stdout
    done = run_cli("node", "info", "/talker", env=ros_env)
    assert (done.returncode, done.stdout.split("\n")) == (0, [*talker_info(), ""]), done.stdout
    done = run_cli("node", "info", "/nobody", env=ros_env)  # ros2cli's message: on stderr
    assert (done.returncode, done.stdout) == (1, ""), done.stdout
    assert done.stderr.splitlines()[-1] == "Unable to find node '/nobody'", done.stderr
    done = run_cli("node", "info", env=ros_env)  # argparse: usage and error on stderr, exit 2
    assert (done.returncode, done.stdout) == (2, ""), done.stdout
    assert done.stderr.splitlines()[-1] == (
        "ros2-classroom node info: error: the following arguments are required: node_name"
    ), done.stderr
    done = run_cli("topic", "-h", env=ros_env)  # options before the verb reach the verbs
    assert done.returncode == 0 and done.stdout.startswith(
        "usage: ros2-classroom topic [-h] [--include-hidden-topics]\n"
    ), done.stdout + done.stderr
    done = run_cli("topic", "type", "/nope", env=ros_env)  # stdout as ros2's: empty
    assert (done.returncode, done.stdout) == (1, "")
    assert "no topic '/nope' on the graph" in done.stderr
