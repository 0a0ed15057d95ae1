"""common_interfaces types our nodes never use, the CLI face, `topic hz` accuracy, bad input."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import threading

import pytest
from geometry_msgs.msg import Twist
from rclpy.callback_groups import ReentrantCallbackGroup
from std_srvs.srv import SetBool, Trigger

from app import PROJECT_ROOT
from app.ros.context import Limits
from tests.conftest import run_cli, wait_until
from tests.integration.conftest import one_error_line

pytestmark = pytest.mark.ros

RATE_HZ = 20.0


def cli(env: dict[str, str], *words: str, timeout: float = 60) -> subprocess.CompletedProcess:
    return run_cli(*words, env=env, timeout=timeout)


def test_set_bool_service_and_twist_topic(probe, ros2):
    calls: list[bool] = []

    def on_set_bool(request: SetBool.Request, response: SetBool.Response) -> SetBool.Response:
        calls.append(request.data)
        response.success = request.data
        response.message = f"motor {'on' if request.data else 'off'}"
        return response

    probe.node.create_service(SetBool, "/probe/enable_motor", on_set_bool)
    code, lines = ros2("service call /probe/enable_motor std_srvs/srv/SetBool '{data: true}'")
    assert code == 0, lines
    assert "std_srvs.srv.SetBool_Response(success=True, message='motor on')" in lines
    assert calls == [True]

    received: list[Twist] = []
    probe.node.create_subscription(Twist, "/cmd_vel", received.append, 10)
    code, lines = ros2(
        "topic pub --once /cmd_vel geometry_msgs/msg/Twist "
        "'{linear: {x: 0.5}, angular: {z: -1.25}}'"
    )
    assert code == 0, lines
    assert "publisher: beginning loop" in lines
    wait_until(lambda: received, timeout=15, what="the Twist on /cmd_vel")
    assert received[0].linear.x == 0.5 and received[0].angular.z == -1.25

    # echo a type no catalog node uses, published from another thread of this test
    stop = threading.Event()

    def keep_publishing() -> None:
        publisher = probe.node.create_publisher(Twist, "/turtle/cmd_vel", 10)
        while not stop.wait(0.05):
            publisher.publish(Twist(linear=Twist().linear.__class__(x=2.0)))

    thread = threading.Thread(target=keep_publishing, daemon=True)
    thread.start()
    try:
        out = ros2.until("topic echo /turtle/cmd_vel --once", "linear:")
        assert out.splitlines()[:4] == ["linear:", "  x: 2.0", "  y: 0.0", "  z: 0.0"]
        code, lines = ros2("topic echo /turtle/cmd_vel --field linear.x")
        assert lines[:2] == ["2.0", "---"]
    finally:
        stop.set()
        thread.join()


def test_cli_face_and_topic_hz_within_two_percent(ros_env, ros2):
    publisher = subprocess.Popen(
        [
            sys.executable, "-m", "app", "topic", "pub", "-r", str(RATE_HZ),
            "/rate_probe", "std_msgs/msg/Float64", "{data: 1.5}",
        ],
        cwd=PROJECT_ROOT, env=ros_env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )  # fmt: skip
    try:
        ros2.until("topic list", "/rate_probe")
        ros2.until("topic hz /rate_probe", "average rate", limits=Limits(max_seconds=2.0))
        # A 5 s window; on a loaded 2-core machine one window may catch a stalled
        # publisher, so up to three windows are measured and one must be within 2 %.
        measured = []
        for _attempt in range(3):
            code, lines = ros2("topic hz /rate_probe", Limits(max_seconds=5.0))
            rates = [
                float(m.group(1)) for ln in lines if (m := re.match(r"average rate: (\S+)", ln))
            ]
            assert rates, lines
            measured.append(rates[-1])
            if abs(rates[-1] - RATE_HZ) / RATE_HZ < 0.02:
                break
        assert abs(measured[-1] - RATE_HZ) / RATE_HZ < 0.02, measured
        assert re.search(r"window: \d+", "\n".join(lines))
        code, lines = ros2("topic bw /rate_probe", Limits(max_seconds=2.5))
        assert re.search(r"B/s from \d+ messages", "\n".join(lines)), lines

        # A fresh process discovers the graph as it goes (ros2 without its daemon
        # too): allow a second look when the machine is busy.
        for _attempt in range(3):
            done = cli(ros_env, "topic", "list", "-t")
            assert done.returncode == 0, done.stderr
            if "/rate_probe [std_msgs/msg/Float64]" in done.stdout.splitlines():
                break
        assert "/rate_probe [std_msgs/msg/Float64]" in done.stdout.splitlines(), done.stdout
        done = cli(ros_env, "topic", "echo", "/rate_probe", "--once")
        assert done.stdout.splitlines()[:2] == ["data: 1.5", "---"], done.stdout
        done = cli(ros_env, "service", "call", "/nope", "std_srvs/srv/Trigger", "{}")
        assert done.returncode == 1
        assert "error: service '/nope' is not available" in done.stdout
        assert "Traceback" not in done.stdout + done.stderr
    finally:
        publisher.send_signal(signal.SIGINT)
        output, _ = publisher.communicate(timeout=15)
    assert "publishing #1: std_msgs.msg.Float64(data=1.5)" in output
    # stopped by Ctrl+C, cleanly, as ros2 ends: nothing more printed, SIGTERM's number
    assert publisher.returncode == 15, output
    assert "(stopped)" not in output
    assert "Traceback" not in output


def test_bad_input_gives_one_clear_line(probe, ros2):
    fast = Limits(max_seconds=2.0, service_timeout=2.0)
    group = ReentrantCallbackGroup()

    release = threading.Event()

    def answer_too_late(request: Trigger.Request, response: Trigger.Response):
        release.wait(10)
        return response

    probe.node.create_service(Trigger, "/probe/stuck", answer_too_late, callback_group=group)
    cases = {
        "topic pub /x std_msgs/msg/String '{data: [unclosed'": "malformed YAML",
        "topic pub /x geometry_msgs/msg/Twist '{linear: {x: fast}}'": (
            "field 'linear.x' (double) expects a number, got text ('fast')"
        ),
        "topic pub /x geometry_msgs/msg/Twist '{linear: {w: 1}}'": "unknown field 'linear.w'",
        "service call /probe/stuck std_srvs/srv/Trigger": "no answer from service '/probe/stuck'",
        "service call /absent std_srvs/srv/Trigger": "service '/absent' is not available",
        "service call /probe/stuck std_srvs/srv/SetBool '{data: 3}'": (
            "expects true or false, got an integer (3)"
        ),
        "service call /probe/stuck std_srvs/srv/SetBool '{data: true}'": (
            "has type std_srvs/srv/Trigger, not std_srvs/srv/SetBool"
        ),
        "topic echo 'bad name!' std_msgs/msg/String": "",
        'ros2 service call "/unterminated': "No closing quotation",
    }
    # Where ros2cli has its own words, they are printed as it prints them.
    ros2cli_cases = {
        "topic echo /no_such_topic": (
            1,
            [
                "WARNING: topic [/no_such_topic] does not appear to be published yet",
                "Could not determine the type for the passed topic",
            ],
        ),
        "topic pub /x std_msgs/msg/Nope '{}'": (1, ["The passed message type is invalid"]),
        "service call /x std_srvs/srv/Nope": (1, ["The passed service type is invalid"]),
        "action send_goal /fib tutorial_interfaces/action/Nope '{}'": (
            1,
            ["The passed action type is invalid"],
        ),
        "interface show nope/msg/Nothing": (1, ["Unknown package 'nope'"]),
        "interface show std_msgs/String": (
            1,
            ["Invalid name 'std_msgs/String'. Expected three parts separated by '/'"],
        ),
        # ros2cli looks for the node among the managed ones only
        "lifecycle set /test_probe configure": (1, ["Node not found"]),
        "topic pub /x std_msgs/msg/String 'just text'": (
            1,
            ["The passed value needs to be a dictionary in YAML format"],
        ),
    }
    try:
        for text, expected in cases.items():
            code, lines = ros2(text, fast)
            line = one_error_line(lines)
            assert code != 0, (text, lines)
            assert expected in line, (text, line)
        for text, (want_code, want_lines) in ros2cli_cases.items():
            assert ros2(text, fast) == (want_code, want_lines), text
        code, lines = ros2("ros2 topic frobnicate", fast)
        assert code == 2, lines  # argparse: the usage, then "PROG: error: ..."
        assert lines[:2] == [
            "usage: ros2 topic [-h] [--include-hidden-topics]",
            "                  Call `ros2 topic <command> -h` for more detailed usage. ...",
        ], lines
        assert lines[-1] == (
            "ros2 topic: error: argument Call `ros2 topic <command> -h` for more detailed "
            "usage.: invalid choice: 'frobnicate' (choose from 'bw', 'delay', 'echo', 'find', "
            "'hz', 'info', 'list', 'pub', 'type')"
        ), lines
    finally:
        release.set()
    # still working afterwards
    code, lines = ros2("node list")
    assert "/test_probe" in lines
