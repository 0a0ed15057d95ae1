"""What is on the ROS graph right now, as plain data, and waiting for something to appear.

One ``GraphSnapshot`` is taken by ``snapshot(node)`` from the dashboard's own
node; panels and lesson checks read snapshots, never the rclpy node. The
live/ghost rule (``endpoint_owners``) is the one place that decides whether
a listed node name is a running node.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from rclpy.action.graph import (
    get_action_client_names_and_types_by_node,
    get_action_server_names_and_types_by_node,
)
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node

from app.ros.context import CallContext
from app.ros.convert import RosType, import_type
from app.ros.errors import Ros2Error
from app.ros.names import (
    ACTION_MARKER,
    QUIET_TOPICS,
    is_hidden_node,
    is_internal_topic,
    node_fqn,
    own_nodes,
    split_node_name,
)


@dataclass(frozen=True)
class TopicInfo:
    name: str
    types: tuple[str, ...]
    publishers: int
    subscribers: int
    # Of those, the endpoints of the node that looked (the dashboard's own taps).
    own_publishers: int = 0
    own_subscribers: int = 0


@dataclass(frozen=True)
class GraphSnapshot:
    nodes: tuple[str, ...] = ()
    topics: tuple[TopicInfo, ...] = ()
    services: tuple[tuple[str, tuple[str, ...]], ...] = ()
    actions: tuple[str, ...] = field(default=())
    # Names DDS still lists but that own no endpoint any more (see endpoint_owners).
    ghosts: tuple[str, ...] = ()

    def topic(self, name: str) -> TopicInfo | None:
        return next((t for t in self.topics if t.name == name), None)

    def has_node(self, fqn: str) -> bool:
        return fqn in self.nodes

    def publishers(self, topic: str) -> int:
        info = self.topic(topic)
        return info.publishers if info else 0

    def nodes_serving(self, suffix: str, type_text: str | None = None) -> list[str]:
        """Nodes that offer ``<node><suffix>`` (e.g. '/get_state'), optionally of one type."""
        return sorted(
            name[: -len(suffix)] or "/"
            for name, types in self.services
            if name.endswith(suffix) and (type_text is None or type_text in types)
        )


def endpoint_owners(node: Node) -> tuple[list[TopicInfo], set[str]]:
    """Every topic with its counts, and the nodes that own at least one endpoint.

    Owning an endpoint is what tells a live node from a leftover name. Every
    rclpy node publishes /rosout and /parameter_events. The graph cache learns
    node names from one DDS message and endpoints from others; when a process
    leaves while its messages cross, its name can outlive its endpoints for
    good (a "ghost" in `ros2 node list`). Asking by name would not do: a
    ghost and a restarted node of the same name share it, and the query
    answers for whichever comes first. Endpoint records carry their owner.
    """
    topics: list[TopicInfo] = []
    owners: set[str] = set()
    me = (node.get_name(), node.get_namespace())
    for name, types in node.get_topic_names_and_types():
        publishers = _endpoint_nodes(node, name, publishers=True)
        subscribers = _endpoint_nodes(node, name, publishers=False)
        owners.update(node_fqn(*e) for e in (*publishers, *subscribers))
        topics.append(
            TopicInfo(
                name,
                tuple(types),
                len(publishers),
                len(subscribers),
                publishers.count(me),
                subscribers.count(me),
            )
        )
    return topics, owners


def _endpoint_nodes(node: Node, topic: str, *, publishers: bool) -> list[tuple[str, str]]:
    """Who owns each publisher (or subscription) of a listed topic: (node name, namespace).

    What ``get_publishers_info_by_topic`` (or subscriptions) answers, without the
    ``TopicEndpointInfo`` and QoS objects rclpy builds for every endpoint: those were
    70 % of the dashboard's graph snapshot, taken once a second (issue 43's idle CPU).
    The topic is already a full name, as the graph listed it (rclpy would expand it).
    """
    query: Callable[[object, str, bool], list[dict[str, Any]]] = (
        _rclpy.rclpy_get_publishers_info_by_topic
        if publishers
        else _rclpy.rclpy_get_subscriptions_info_by_topic
    )
    with node.handle:
        found = query(node.handle, topic, False)
    return [(e["node_name"], e["node_namespace"]) for e in found]


def subscriptions_ours_and_others(node: Node, topic: str) -> tuple[int, int]:
    """Subscriptions on ``topic``: (``node``'s and its attempt's recording's, everyone
    else's). Checks and probes count a learner's readers without their own."""
    ours = own_nodes(node.get_name(), node.get_namespace())
    owners = [(i.node_name, i.node_namespace) for i in node.get_subscriptions_info_by_topic(topic)]
    mine = sum(owner in ours for owner in owners)
    return mine, len(owners) - mine


def _live_and_ghosts(node: Node, owners: set[str]) -> tuple[list[str], list[str]]:
    listed = {node_fqn(n, ns) for n, ns in node.get_node_names_and_namespaces()}
    return sorted(listed & owners), sorted(listed - owners)


def live_and_ghost_nodes(node: Node) -> tuple[list[str], list[str]]:
    """Listed node names split into live ones and ghosts (see endpoint_owners)."""
    return _live_and_ghosts(node, endpoint_owners(node)[1])


def snapshot(node: Node, *, include_hidden: bool = False) -> GraphSnapshot:
    all_topics, owners = endpoint_owners(node)
    nodes, ghosts = _live_and_ghosts(node, owners)
    # Action internals are listed as actions, not topics.
    # Action internals and hidden names ('/_...') are listed only on request, as ros2cli does.
    topics = [t for t in all_topics if include_hidden or not is_internal_topic(t.name)]
    services = []
    actions = set()
    for name, types in node.get_service_names_and_types():
        if ACTION_MARKER in name:
            actions.add(name.split(ACTION_MARKER)[0])
            continue
        services.append((name, tuple(types)))
    return GraphSnapshot(
        nodes=tuple(n for n in nodes if include_hidden or not is_hidden_node(n)),
        topics=tuple(sorted(topics, key=lambda t: t.name)),
        services=tuple(sorted(services)),
        actions=tuple(sorted(actions)),
        ghosts=tuple(ghosts),
    )


# ------------------------------------------------------------ direct queries


def all_nodes(node: Node, include_hidden: bool = False) -> list[str]:
    """Every listed node name (ghosts included, as `ros2 node list` shows them)."""
    names = sorted(node_fqn(n, ns) for n, ns in node.get_node_names_and_namespaces())
    return names if include_hidden else [n for n in names if not is_hidden_node(n)]


def topic_types(node: Node, include_hidden: bool = False) -> dict[str, list[str]]:
    return {
        name: list(types)
        for name, types in node.get_topic_names_and_types()
        if include_hidden or not is_internal_topic(name)
    }


@dataclass(frozen=True)
class NodeEndpoints:
    """What one node offers and uses, as `ros2 node info` lists it (name -> type)."""

    name: str
    publishes: dict[str, str]
    subscribes: dict[str, str]
    servers: dict[str, str]
    clients: dict[str, str]
    action_servers: dict[str, str]
    action_clients: dict[str, str]


def _first_types(pairs: list[tuple[str, list[str]]]) -> dict[str, str]:
    return {name: types[0] for name, types in pairs if types}


def node_endpoints(node: Node, fqn: str) -> NodeEndpoints | None:
    """One node's endpoints from the local graph cache; None if it just vanished."""
    name, namespace = split_node_name(fqn)
    try:
        return NodeEndpoints(
            fqn,
            _first_types(node.get_publisher_names_and_types_by_node(name, namespace)),
            _first_types(node.get_subscriber_names_and_types_by_node(name, namespace)),
            _first_types(node.get_service_names_and_types_by_node(name, namespace)),
            _first_types(node.get_client_names_and_types_by_node(name, namespace)),
            _first_types(get_action_server_names_and_types_by_node(node, name, namespace)),
            _first_types(get_action_client_names_and_types_by_node(node, name, namespace)),
        )
    except Exception:  # the node left between listing and asking
        return None


def published_topics(node: Node, fqn: str) -> dict[str, str]:
    """Topic -> type of what one node publishes, without /rosout and friends."""
    found = node_endpoints(node, fqn)
    if found is None:
        return {}
    return {
        topic: type_text
        for topic, type_text in found.publishes.items()
        if topic not in QUIET_TOPICS
        and not is_internal_topic(topic)
        and not topic.endswith("/transition_event")
    }


# ------------------------------------------------------------------ waiting


def wait_for_graph(ctx: CallContext, present: Callable[[], bool]) -> bool:
    """True once ``present()``; a fresh CLI node keeps looking for ``discovery_wait`` s."""
    deadline = time.monotonic() + ctx.limits.discovery_wait
    while not present():
        if time.monotonic() >= deadline:
            return False
        ctx.sleep(0.1)
    return True


def require_node(ctx: CallContext, fqn: str) -> str:
    """The fully qualified name of a node on the graph, or one clear error."""
    if not fqn.startswith("/"):
        fqn = "/" + fqn
    if not wait_for_graph(ctx, lambda: fqn in all_nodes(ctx.node, include_hidden=True)):
        raise Ros2Error(f"node '{fqn}' is not on the graph (see `ros2 node list`)")
    return fqn


def resolve_topic_type(ctx: CallContext, topic: str, given: str | None) -> RosType:
    """The message class for ``topic``: the given type, else the one on the graph."""
    if given:
        return import_type(given, "msg")
    wait_for_graph(ctx, lambda: topic in topic_types(ctx.node, include_hidden=True))
    types = topic_types(ctx.node, include_hidden=True).get(topic)
    if not types:
        raise Ros2Error(
            f"topic '{topic}' is not on the graph (see `ros2 topic list`); "
            "to wait for it anyway, give its type after the topic name"
        )
    if len(types) > 1:
        raise Ros2Error(f"topic '{topic}' has several types ({', '.join(types)}); give one")
    return import_type(types[0], "msg")
