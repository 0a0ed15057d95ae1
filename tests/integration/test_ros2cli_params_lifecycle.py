"""param and lifecycle verbs against parameters_node and lifecycle_talker."""

from __future__ import annotations

import re

import pytest

from app.ros.context import Limits
from tests.integration.conftest import TEST_LIMITS

pytestmark = pytest.mark.ros

HZ_LIMITS = Limits(max_seconds=3.0, service_timeout=TEST_LIMITS.service_timeout)


def last_rate(lines: list[str]) -> float | None:
    rates = [
        float(m.group(1)) for line in lines if (m := re.match(r"average rate: ([\d.]+)", line))
    ]
    return rates[-1] if rates else None


def test_param_list_get_set_dump(supervisor, ros2):
    supervisor.start("parameters_node")
    out = ros2.until("ros2 param list /parameters_node", "  publish_rate_hz")
    assert {"  greeting", "  shout", "  use_sim_time"} <= set(out.splitlines())

    code, lines = ros2("param get /parameters_node greeting")
    assert lines == ["String value is: Hello"]
    code, lines = ros2("param get /parameters_node publish_rate_hz")
    assert lines == ["Double value is: 2.0"]
    code, lines = ros2("param get /parameters_node no_such_thing")
    # rclpy answers an undeclared name with no value: ros2cli's "Parameter not set", 1
    assert (code, lines) == (1, ["Parameter not set"])

    code, lines = ros2("param set /parameters_node publish_rate_hz 10.0")
    assert (code, lines) == (0, ["Set parameter successful"])
    code, lines = ros2("param set /parameters_node shout true")
    assert lines == ["Set parameter successful"]
    code, lines = ros2("param get /parameters_node shout")
    assert lines == ["Boolean value is: True"]

    # ros2cli's words and exit code 0 when the node refuses a value
    code, lines = ros2("param set /parameters_node publish_rate_hz 100.0")
    assert code == 0 and lines[0].startswith("Setting parameter failed"), lines
    code, lines = ros2("param set /parameters_node greeting '\"  \"'")
    assert lines == ["Setting parameter failed: greeting must not be empty"]

    code, lines = ros2("param dump /parameters_node")
    assert lines[:2] == ["/parameters_node:", "  ros__parameters:"]
    assert "    publish_rate_hz: 10.0" in lines
    assert "    greeting: Hello" in lines

    out = ros2.until("topic echo /greeting --once", "FROM PARAMETERS_NODE")
    assert out.startswith("data: 'HELLO FROM PARAMETERS_NODE #")


def test_lifecycle_walk_with_publish_rate(supervisor, ros2):
    supervisor.start("lifecycle_talker")
    ros2.until("lifecycle nodes", "/lifecycle_talker")
    assert ros2("lifecycle get /lifecycle_talker")[1] == ["unconfigured [1]"]
    code, lines = ros2("ros2 lifecycle list /lifecycle_talker")
    assert lines[:3] == ["- configure [1]", "\tStart: unconfigured", "\tGoal: configuring"]

    code, lines = ros2("lifecycle set /lifecycle_talker activate")
    assert (code, lines) == (
        1,
        ["Unknown transition requested, available ones are:", "- configure [1]", "- shutdown [5]"],
    )

    assert ros2("lifecycle set /lifecycle_talker configure")[1] == ["Transitioning successful"]
    assert ros2("lifecycle get /lifecycle_talker")[1] == ["inactive [2]"]
    assert ros2("lifecycle set /lifecycle_talker activate")[1] == ["Transitioning successful"]
    assert ros2("lifecycle get /lifecycle_talker")[1] == ["active [3]"]
    out = ros2.until("topic hz /lifecycle_chatter", "average rate", limits=HZ_LIMITS)
    rate = last_rate(out.splitlines())
    assert rate is not None and rate > 0.5

    assert ros2("lifecycle set /lifecycle_talker deactivate")[1] == ["Transitioning successful"]
    code, lines = ros2("topic hz /lifecycle_chatter", HZ_LIMITS)
    assert last_rate(lines) is None, lines  # inactive: nothing is published
    assert ros2("lifecycle set /lifecycle_talker 2")[1] == ["Transitioning successful"]  # cleanup
    assert ros2("lifecycle get /lifecycle_talker")[1] == ["unconfigured [1]"]
    assert ros2("lifecycle set /lifecycle_talker shutdown")[1] == ["Transitioning successful"]
    assert ros2("lifecycle get /lifecycle_talker")[1] == ["finalized [4]"]

    code, lines = ros2("lifecycle get /parameters_node_absent")
    assert (code, lines) == (1, ["Node not found"])
