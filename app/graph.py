"""What is on the ROS graph right now, as plain data.

One ``GraphSnapshot`` is taken by ``snapshot(node)`` from the dashboard's own
node; panels and lesson checks read snapshots, never the rclpy node.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from rclpy.node import Node

ACTION_MARKER = "/_action/"


@dataclass(frozen=True)
class TopicInfo:
    name: str
    types: tuple[str, ...]
    publishers: int
    subscribers: int


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


def _fqn(name: str, namespace: str) -> str:
    return f"{namespace.rstrip('/')}/{name}"


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
    topics, owners = [], set()
    for name, types in node.get_topic_names_and_types():
        publishers = node.get_publishers_info_by_topic(name)
        subscribers = node.get_subscriptions_info_by_topic(name)
        owners.update(_fqn(e.node_name, e.node_namespace) for e in (*publishers, *subscribers))
        topics.append(TopicInfo(name, tuple(types), len(publishers), len(subscribers)))
    return topics, owners


def _live_and_ghosts(node: Node, owners: set[str]) -> tuple[list[str], list[str]]:
    listed = {_fqn(n, ns) for n, ns in node.get_node_names_and_namespaces()}
    return sorted(listed & owners), sorted(listed - owners)


def live_and_ghost_nodes(node: Node) -> tuple[list[str], list[str]]:
    """Listed node names split into live ones and ghosts (see endpoint_owners)."""
    return _live_and_ghosts(node, endpoint_owners(node)[1])


def snapshot(node: Node, *, include_hidden: bool = False) -> GraphSnapshot:
    all_topics, owners = endpoint_owners(node)
    nodes, ghosts = _live_and_ghosts(node, owners)
    # Action internals are listed as actions, not topics.
    topics = [t for t in all_topics if include_hidden or ACTION_MARKER not in t.name]
    services = []
    actions = set()
    for name, types in node.get_service_names_and_types():
        if ACTION_MARKER in name:
            actions.add(name.split(ACTION_MARKER)[0])
            continue
        services.append((name, tuple(types)))
    return GraphSnapshot(
        nodes=tuple(n for n in nodes if include_hidden or not n.rsplit("/", 1)[-1].startswith("_")),
        topics=tuple(sorted(topics, key=lambda t: t.name)),
        services=tuple(sorted(services)),
        actions=tuple(sorted(actions)),
        ghosts=tuple(ghosts),
    )
