"""node/topic/service/action verbs against real catalog nodes, outputs checked."""

from __future__ import annotations

import re

import pytest

from app.ros.context import Limits

pytestmark = pytest.mark.ros


def test_node_topic_service_and_action_verbs(supervisor, ros2):
    for name in ("talker", "add_two_ints_server", "fibonacci_action_server"):
        supervisor.start(name)

    out = ros2.until(
        "ros2 node list",
        lambda o: all(
            n in o for n in ("/talker", "/add_two_ints_server", "/fibonacci_action_server")
        ),
    )
    assert "/test_probe" in out.splitlines()

    out = ros2.until("node info /talker", "/chatter: std_msgs/msg/String")
    assert out.splitlines()[0] == "/talker"
    publishers = out.split("  Publishers:")[1].split("  Service Servers:")[0]
    assert "/chatter: std_msgs/msg/String" in publishers
    assert "/talker/get_parameters: rcl_interfaces/srv/GetParameters" in out

    out = ros2.until("topic list -t", "/chatter [std_msgs/msg/String]")
    assert "/rosout [rcl_interfaces/msg/Log]" in out.splitlines()

    out = ros2.until("topic info /chatter --verbose", "Node name: talker")
    assert "Type: std_msgs/msg/String" in out
    assert "Publisher count: 1" in out
    assert "Endpoint type: PUBLISHER" in out
    assert "  Reliability: RELIABLE" in out
    assert "  Durability: VOLATILE" in out

    code, lines = ros2("ros2 topic echo /chatter --once")
    assert code == 0
    assert re.fullmatch(r"data: 'Hello World: \d+'", lines[0]), lines
    assert lines[1] == "---"
    code, lines = ros2("topic echo /chatter --field data")
    numbers = [
        int(m.group(1)) for line in lines if (m := re.fullmatch(r"Hello World: (\d+)", line))
    ]
    assert len(numbers) == 3 and numbers == sorted(numbers), lines  # bounded: 3 messages
    # --qos-*: the subscription as asked (best effort hears a reliable publisher; a
    # transient local one matches no volatile publisher, so nothing comes)
    code, lines = ros2("topic echo --once --qos-reliability best_effort /chatter")
    assert code == 0 and re.fullmatch(r"data: 'Hello World: \d+'", lines[0]), lines
    code, lines = ros2(
        "topic echo --once --qos-durability transient_local /chatter", Limits(max_seconds=2.0)
    )
    assert (code, lines) == (0, ["(no message on /chatter within 2 s)"])

    out = ros2.until("service list -t", "/add_two_ints [tutorial_interfaces/srv/AddTwoInts]")
    code, lines = ros2("service type /add_two_ints")
    assert lines == ["tutorial_interfaces/srv/AddTwoInts"]
    code, lines = ros2(
        "ros2 service call /add_two_ints tutorial_interfaces/srv/AddTwoInts '{a: 2, b: 40}'"
    )
    assert code == 0, lines
    if lines[0] == "waiting for service to become available...":  # not matched yet
        lines = lines[1:]
    assert lines[0] == (
        "requester: making request: tutorial_interfaces.srv.AddTwoInts_Request(a=2, b=40)"
    )
    assert "response:" in lines
    assert "tutorial_interfaces.srv.AddTwoInts_Response(sum=42)" in lines

    ros2.until("action list -t", "/fibonacci [tutorial_interfaces/action/Fibonacci]")
    out = ros2.until("action info /fibonacci", "Action servers: 1")
    assert "    /fibonacci_action_server" in out.splitlines()
    assert "Action clients: 0" in out

    # 0.2 s a step: the goal's 6 feedback messages span 1.2 s. At 0.05 s the whole goal took
    # 0.3 s, and on busy cores our fresh client's feedback reader matched the server's
    # writer only after the first messages had gone (2 of 6 arrived, as upstream's would).
    code, lines = ros2("param set /fibonacci_action_server step_period 0.2")
    assert lines == ["Set parameter successful"]
    code, lines = ros2(
        "ros2 action send_goal /fibonacci tutorial_interfaces/action/Fibonacci "
        '"{order: 6}" --feedback'
    )
    out = "\n".join(lines)
    assert code == 0, out
    assert re.search(r"Goal accepted with ID: [0-9a-f]{32}", out)
    assert out.count("Feedback:") >= 3
    # YAML block style, as rosidl_runtime_py's message_to_yaml prints it
    assert "Feedback:\n    partial_sequence:\n- 0\n- 1\n- 1\n\n" in out
    assert "Result:\n    sequence:\n- 0\n- 1\n- 1\n- 2\n- 3\n- 5\n- 8\n\n" in out
    assert lines[-1] == "Goal finished with status: SUCCEEDED"

    code, lines = ros2("ros2 node info /nobody")
    assert (code, lines) == (1, ["Unable to find node '/nobody'"])  # ros2cli's words
