"""The live/ghost rule of app.graph on a recorded graph (pure logic, no DDS).

The real graph queries are exercised by the integration and browser tests;
here a recorded answer set shows the rule itself, including the case that
made it necessary: a leftover name and a restarted node sharing one name.
"""

from __future__ import annotations

import pytest

from app.ros import graph as graph_module
from app.ros.graph import live_and_ghost_nodes, snapshot


@pytest.fixture(autouse=True)
def recorded_endpoints(monkeypatch: pytest.MonkeyPatch) -> None:
    """app.ros.graph asks rclpy's own binding for each topic's endpoint owners; here, the
    recorded graph answers instead."""
    monkeypatch.setattr(
        graph_module,
        "_endpoint_nodes",
        lambda node, topic, *, publishers: node.endpoint_nodes(topic, publishers),
    )


class RecordedGraph:
    """Answers the graph queries app.graph asks, from fixed data (it asks as /observer)."""

    def __init__(self, names, publishers, subscribers=None, services=()):
        self.names = names
        self.publishers = publishers
        self.subscribers = subscribers or {}
        self.services = list(services)

    def get_name(self):
        return "observer"

    def get_namespace(self):
        return "/"

    def get_node_names_and_namespaces(self):
        return list(self.names)

    def get_topic_names_and_types(self):
        topics = sorted(set(self.publishers) | set(self.subscribers))
        return [(t, ["std_msgs/msg/String"]) for t in topics]

    def endpoint_nodes(self, topic, publishers):
        return list((self.publishers if publishers else self.subscribers).get(topic, ()))

    def get_service_names_and_types(self):
        return self.services


def test_a_restarted_node_is_live_even_while_a_ghost_shares_its_name():
    graph = RecordedGraph(
        names=[("talker", "/"), ("talker", "/"), ("classroom_dashboard", "/")],
        publishers={"/chatter": [("talker", "/")], "/rosout": [("classroom_dashboard", "/")]},
    )
    live, ghosts = live_and_ghost_nodes(graph)
    assert live == ["/classroom_dashboard", "/talker"]
    assert ghosts == []


def test_a_name_that_owns_no_endpoint_is_a_ghost_not_a_node():
    graph = RecordedGraph(
        names=[("talker", "/"), ("listener", "/")],
        publishers={"/rosout": [("listener", "/")]},
        subscribers={"/chatter": [("listener", "/")]},
    )
    snap = snapshot(graph)
    assert snap.nodes == ("/listener",)
    assert snap.ghosts == ("/talker",)
    assert snap.topic("/chatter").subscribers == 1
    assert snap.topic("/chatter").publishers == 0


def test_endpoints_of_an_unlisted_node_do_not_invent_a_node():
    graph = RecordedGraph(names=[], publishers={"/chatter": [("talker", "/demo")]})
    assert live_and_ghost_nodes(graph) == ([], [])
    assert snapshot(graph).topic("/chatter").publishers == 1
