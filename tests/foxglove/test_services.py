"""ROS services through the Foxglove bridge, called as Foxglove's Service Call panel calls them.

A real server (the catalog's add_two_ints_server, its own process) answers
CDR requests the test serializes with rclpy; a slow server in a second
participant of this process shows the bounds: a timeout, and a client that
asks too much at once.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest
from mcap_ros2._dynamic import serialize_dynamic

from tests.conftest import wait_until
from tests.foxglove.client import FoxgloveClient

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

ADD = "tutorial_interfaces/srv/AddTwoInts"
DISCOVERY_SEC = 45.0  # a node starting on a loaded machine, then DDS discovery


def _serve(probe: Any, **limits: Any) -> Any:
    from app.foxglove import FoxgloveBridge
    from app.foxglove.limits import BridgeLimits

    bridge = FoxgloveBridge(probe.node, port=0, limits=BridgeLimits(**limits))
    bridge.start()
    return bridge


@pytest.fixture
def client(probe) -> Iterator[FoxgloveClient]:
    bridge = _serve(probe)
    fox = FoxgloveClient(bridge.url)
    fox.wait_for(lambda: fox.server_info, 10, "serverInfo")
    yield fox
    fox.close()
    bridge.close()


def test_a_ros_service_is_advertised_and_answers_cdr_calls(supervisor, client):
    from rclpy.serialization import deserialize_message, serialize_message
    from tutorial_interfaces.srv import AddTwoInts

    assert "services" in client.server_info["capabilities"]
    supervisor.start("add_two_ints_server")
    service = client.wait_for(
        lambda: client.service("/add_two_ints"), DISCOVERY_SEC, "/add_two_ints advertised"
    )
    assert service["type"] == ADD
    request, response = service["request"], service["response"]
    assert (request["encoding"], request["schemaEncoding"]) == ("cdr", "ros2msg")
    assert request["schemaName"] == f"{ADD}_Request"
    assert request["schema"].split() == ["int64", "a", "int64", "b"]
    assert response["schemaName"] == f"{ADD}_Response"
    assert response["schema"].split() == ["int64", "sum"]
    # Every node's parameter services are left out (the server has six).
    assert not [s for s in client.services.values() if "parameter" in s["name"]]

    result = client.call(service["id"], serialize_message(AddTwoInts.Request(a=2, b=40)))
    assert result.failure is None and result.encoding == "cdr"
    assert deserialize_message(result.payload, AddTwoInts.Response).sum == 42
    # As Foxglove would: a request built from nothing but the advertised schema text.
    encode = serialize_dynamic(request["schemaName"], request["schema"])[request["schemaName"]]
    result = client.call(service["id"], bytes(encode({"a": -7, "b": 3})))
    assert deserialize_message(result.payload, AddTwoInts.Response).sum == -4

    garbage = client.call(service["id"], b"\x00\x01\x00\x00\x05")
    assert garbage.payload is None and "not a valid CDR" in (garbage.failure or "")
    unknown = client.call(service["id"] + 1000, serialize_message(AddTwoInts.Request()))
    assert unknown.payload is None and unknown.failure
    # Still serving.
    result = client.call(service["id"], serialize_message(AddTwoInts.Request(a=1, b=1)))
    assert deserialize_message(result.payload, AddTwoInts.Response).sum == 2


def test_a_slow_service_times_out_calls_are_bounded_and_a_gone_service_goes(probe):
    from rclpy.serialization import serialize_message
    from tutorial_interfaces.srv import AddTwoInts

    from app.ros.runtime import RosRuntime

    slow = RosRuntime("slow_adder")

    def answer_late(request: Any, response: Any) -> Any:
        time.sleep(1.5)
        response.sum = request.a + request.b
        return response

    server = slow.node.create_service(AddTwoInts, "/slow_add", answer_late)
    bridge = _serve(probe, call_timeout_sec=0.7, calls_per_client=2, gone_after_sec=0.5)
    fox = FoxgloveClient(bridge.url)
    try:
        service = fox.wait_for(lambda: fox.service("/slow_add"), DISCOVERY_SEC, "/slow_add")
        payload = serialize_message(AddTwoInts.Request(a=1, b=2))
        calls = [fox.call_service(service["id"], payload) for _ in range(3)]
        results = [fox.wait_for(lambda c=c: fox.call_result(c), 15, f"call {c}") for c in calls]
        failures = sorted(r.failure or "" for r in results)
        assert all(r.payload is None for r in results), results
        assert sum("too many calls" in f for f in failures) == 1, failures
        assert sum("did not answer" in f for f in failures) == 2, failures
        assert any("too many calls" in n for n in bridge.recent_notes())

        slow.node.destroy_service(server)
        fox.wait_for(lambda: fox.service("/slow_add") is None, 30, "/slow_add unadvertised")
        wait_until(lambda: bridge.counts().services == 0, 10, what="the bridge let it go")
    finally:
        fox.close()
        bridge.close()
        slow.shutdown()


def test_parameters_are_read_and_set_by_their_foxglove_names(probe, client):
    from rclpy.parameter import Parameter

    from app.ros.runtime import RosRuntime

    holder = RosRuntime("param_holder")
    holder.node.declare_parameter("greeting", "hello")
    holder.node.declare_parameter("gain", 1.5)
    try:
        gain, greeting = "/param_holder.gain", "/param_holder.greeting"

        def known() -> dict[str, Any] | None:
            values = client.get_parameters([])  # no names: everything the bridge knows
            return values if gain in values and greeting in values else None

        values = client.wait_for(known, DISCOVERY_SEC, "param_holder's parameters")
        assert (values[gain], values[greeting]) == (1.5, "hello")
        assert client.get_parameters([gain]) == {gain: 1.5}

        # 2 arrives as an integer (JSON): the bridge keeps the parameter a double.
        client.set_parameters({gain: 2, greeting: "bye"})
        client.wait_for(
            lambda: client.get_parameters([gain, greeting]) == {gain: 2.0, greeting: "bye"},
            20,
            "the new values",
        )
        assert holder.node.get_parameter("gain").value == 2.0
        assert holder.node.get_parameter("greeting").type_ == Parameter.Type.STRING

        client.set_parameters({greeting: 5})  # a string parameter: the node refuses
        wait_until(
            lambda: any("could not set /param_holder.greeting" in t for t in client.status_texts()),
            20,
            what="the refusal said",
        )
        assert holder.node.get_parameter("greeting").value == "bye"
    finally:
        holder.shutdown()
