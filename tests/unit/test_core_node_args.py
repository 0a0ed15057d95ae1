"""Client program arguments and QoS parameter parsing, without starting ROS."""

from __future__ import annotations

import subprocess
import sys

import pytest
from rclpy.qos import DurabilityPolicy, ReliabilityPolicy

from app import PROJECT_ROOT
from nodes.add_two_ints_client import parse_operands
from nodes.fibonacci_action_client import parse_order
from nodes.qos_settings import describe, profile_from_names


def run_node(module: str, *args: str) -> subprocess.CompletedProcess[str]:
    # Bad arguments are refused before rclpy.init(): no DDS traffic happens here.
    return subprocess.run(
        [sys.executable, "-m", f"nodes.{module}", *args],
        cwd=PROJECT_ROOT,
        capture_output=True,
        text=True,
        timeout=60,
    )


def test_add_two_ints_client_parses_two_integers():
    assert parse_operands(["2", "-3"]) == (2, -3)
    for bad in ([], ["1"], ["1", "2", "3"], ["one", "2"], ["1", str(2**63)]):
        with pytest.raises(ValueError):
            parse_operands(bad)


@pytest.mark.parametrize(
    "args",
    [(), ("1",), ("1", "two"), ("1", "2", "3", "--ros-args", "-r", "__node:=x")],
)
def test_add_two_ints_client_bad_arguments_give_usage_and_exit_2(args):
    result = run_node("add_two_ints_client", *args)
    assert result.returncode == 2
    assert "usage: add_two_ints_client A B" in result.stderr
    assert "Traceback" not in result.stderr


def test_fibonacci_client_order_argument():
    assert parse_order([]) == 10
    assert parse_order(["5"]) == 5
    for bad in (["x"], ["1", "2"], [str(2**31)]):
        with pytest.raises(ValueError):
            parse_order(bad)
    result = run_node("fibonacci_action_client", "many")
    assert result.returncode == 2 and "usage: fibonacci_action_client" in result.stderr


def test_qos_profile_from_parameter_values():
    profile = profile_from_names("best_effort", "transient_local", 5)
    assert profile.reliability == ReliabilityPolicy.BEST_EFFORT
    assert profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
    assert describe(profile) == "best_effort, transient_local, depth 5"
    with pytest.raises(ValueError, match="reliability must be one of"):
        profile_from_names("sometimes", "volatile", 10)
    with pytest.raises(ValueError, match="durability"):
        profile_from_names("reliable", "forever", 10)
    with pytest.raises(ValueError, match="depth"):
        profile_from_names("reliable", "volatile", 0)


def test_executor_demo_rate_measure():
    from nodes.executor_demo import rate_hz

    assert rate_hz([]) == 0.0 and rate_hz([1.0]) == 0.0
    assert rate_hz([0.0, 0.1, 0.2, 0.3, 0.4]) == pytest.approx(10.0)
    assert rate_hz([0.0, 0.05, 1.0, 1.05, 2.0]) == pytest.approx(2.0)  # starved: bursts
