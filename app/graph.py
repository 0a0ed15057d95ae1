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

    def topic(self, name: str) -> TopicInfo | None:
        return next((t for t in self.topics if t.name == name), None)

    def has_node(self, fqn: str) -> bool:
        return fqn in self.nodes


def _fqn(name: str, namespace: str) -> str:
    return f"{namespace.rstrip('/')}/{name}"


def snapshot(node: Node, *, include_hidden: bool = False) -> GraphSnapshot:
    nodes = sorted(_fqn(n, ns) for n, ns in node.get_node_names_and_namespaces())
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
    )
