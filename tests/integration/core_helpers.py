"""Probe-side helpers for the core tutorial node tests: calls, parameters, output."""

from __future__ import annotations

import time
from typing import Any

import pytest
from rcl_interfaces.msg import SetParametersResult
from rcl_interfaces.srv import SetParameters
from rclpy.parameter import Parameter

from tests.conftest import wait_until

DISCOVERY_TIMEOUT = 30.0  # generous: Fast DDS discovery is slow under CPU load
CALL_TIMEOUT = 20.0


def call_service(probe, srv_type: type, name: str, request: Any, timeout: float = CALL_TIMEOUT):
    """Call a service from the probe node and return the response."""
    client = probe.node.create_client(srv_type, name)
    try:
        wait_until(
            lambda: client.service_is_ready(),
            timeout=DISCOVERY_TIMEOUT,
            interval=0.1,
            what=f"service {name}",
        )
        future = client.call_async(request)
        wait_until(future.done, timeout=timeout, what=f"a response from {name}")
        return future.result()
    finally:
        probe.node.destroy_client(client)


def set_parameters(probe, node_name: str, **values: Any) -> list[SetParametersResult]:
    """``ros2 param set`` from the probe: one result per parameter."""
    request = SetParameters.Request(
        parameters=[
            Parameter(name, value=value).to_parameter_msg() for name, value in values.items()
        ]
    )
    return call_service(probe, SetParameters, f"{node_name}/set_parameters", request).results


def output_has(supervisor, name: str, text: str) -> bool:
    return any(text in line for line in supervisor.output(name))


def wait_for_output(supervisor, name: str, text: str, timeout: float = DISCOVERY_TIMEOUT) -> None:
    """Wait for a line containing ``text``; on timeout, fail showing the latest output."""
    deadline = time.monotonic() + timeout
    while not output_has(supervisor, name, text):
        if time.monotonic() > deadline:
            last = "\n".join(supervisor.output(name, last=20))
            pytest.fail(
                f"timed out after {timeout:.0f} s waiting for {text!r} from {name}:\n{last}"
            )
        time.sleep(0.1)


def node_names(probe) -> set[str]:
    return {f"{ns.rstrip('/')}/{n}" for n, ns in probe.node.get_node_names_and_namespaces()}


def wait_node_gone(probe, name: str) -> None:
    """Wait until node ``name`` has left the graph, as a fresh ``ros2 node list`` would see it.

    The probe's own graph cache is asked first. Fast DDS can keep a stopped
    node there for good (a late discovery-info message re-adds a participant
    that was just removed; ci of 124208b: /my_turtle listed 30 s after it
    exited). So if the probe still lists it after half the timeout, a new
    participant is asked, once it sees the probe itself (so its discovery is done).
    """
    from app.ros.runtime import RosRuntime

    deadline = time.monotonic() + DISCOVERY_TIMEOUT / 2
    while time.monotonic() < deadline:
        if name not in node_names(probe):
            return
        time.sleep(0.05)
    witness = probe.node.get_fully_qualified_name()
    fresh = RosRuntime("test_fresh_probe", quiet=True)
    try:
        wait_until(
            lambda: witness in node_names(fresh),
            timeout=DISCOVERY_TIMEOUT,
            what=f"a fresh participant to see {witness}",
        )
        wait_until(
            lambda: name not in node_names(fresh),
            timeout=DISCOVERY_TIMEOUT / 2,
            what=lambda: f"{name} to leave the graph: a fresh participant sees {node_names(fresh)}",
        )
    finally:
        fresh.shutdown()
