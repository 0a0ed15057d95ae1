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
    # Names DDS still lists but that have no endpoints left (see is_ghost).
    ghosts: tuple[str, ...] = ()

    def topic(self, name: str) -> TopicInfo | None:
        return next((t for t in self.topics if t.name == name), None)

    def has_node(self, fqn: str) -> bool:
        return fqn in self.nodes


def _fqn(name: str, namespace: str) -> str:
    return f"{namespace.rstrip('/')}/{name}"


def is_ghost(node: Node, name: str, namespace: str) -> bool:
    """A listed node without a single publisher is a leftover, not a live node.

    Every rclpy node publishes /rosout and /parameter_events. The graph cache
    learns node names from one DDS message and endpoints from others; when a
    process leaves while its messages cross, the name can outlive its
    endpoints for good (a "ghost" in `ros2 node list`). Its endpoints are
    reliably removed, so an empty endpoint list tells a ghost apart.
    """
    try:
        return not node.get_publisher_names_and_types_by_node(name, namespace)
    except Exception:  # noqa: BLE001 - the name vanished between two queries
        return True


def snapshot(node: Node, *, include_hidden: bool = False) -> GraphSnapshot:
    live, ghosts = [], []
    for name, namespace in node.get_node_names_and_namespaces():
        (ghosts if is_ghost(node, name, namespace) else live).append(_fqn(name, namespace))
    nodes = sorted(live)
    topics = []
    for name, types in node.get_topic_names_and_types():
        if not include_hidden and ACTION_MARKER in name:
            continue  # action internals are listed as actions
        topics.append(
            TopicInfo(
                name,
                tuple(types),
                node.count_publishers(name),
                node.count_subscribers(name),
            )
        )
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
        ghosts=tuple(sorted(ghosts)),
    )
