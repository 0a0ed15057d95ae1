"""Which topics the scene can draw, and what to tell the learner about each.

Pure functions over a :class:`~app.graph.GraphSnapshot`, so the picker's
choices and notes are unit-testable without a ROS graph.
"""

from __future__ import annotations

from app.ros.graph import GraphSnapshot

NONE = "(none)"

CLOUD_TYPES = ("sensor_msgs/msg/PointCloud2",)
IMAGE_TYPES = ("sensor_msgs/msg/Image",)
MARKER_TYPES = ("visualization_msgs/msg/Marker", "visualization_msgs/msg/MarkerArray")
JOINT_TYPES = ("sensor_msgs/msg/JointState",)
POINT_TYPES = ("geometry_msgs/msg/PointStamped",)
POSE_TYPES = ("geometry_msgs/msg/PoseStamped",)

STALE_AFTER_SEC = 3.0

# What the desk (the camera lesson's base_link and camera marks, and its arm) draws.
DESK_TYPES = JOINT_TYPES + POINT_TYPES + POSE_TYPES


def desk_in_use(graph: GraphSnapshot | None) -> bool:
    """Whether another node publishes something the desk draws (joint angles, a stamped
    point or pose): without one, its frames would stand for a camera and arm that are not
    there (they stayed on the 3D view of every later lesson)."""
    if graph is None:
        return False
    return any(
        t.publishers > t.own_publishers and any(ty in DESK_TYPES for ty in t.types)
        for t in graph.topics
    )


def drawable_topics(graph: GraphSnapshot | None, types: tuple[str, ...]) -> list[str]:
    """Topics whose advertised type is one of ``types``, sorted by name."""
    if graph is None:
        return []
    return sorted(t.name for t in graph.topics if any(ty in types for ty in t.types))


def options(graph: GraphSnapshot | None, types: tuple[str, ...], current: str) -> list[str]:
    """Dropdown choices: "(none)", every drawable topic, and the current pick even if gone."""
    found = drawable_topics(graph, types)
    if current != NONE and current not in found:
        found.append(current)
    return [NONE, *found]


def liveness_note(
    graph: GraphSnapshot | None,
    topic: str,
    received: int,
    seconds_since_last: float | None,
    latched: bool = False,
) -> str:
    """One line for a beginner: is anything arriving, and if not, why probably not.

    ``latched``: the topic is published once and kept (a map): silence is normal.
    """
    if topic == NONE:
        return "Pick a topic to draw it."
    info = graph.topic(topic) if graph else None
    publishers = info.publishers if info else 0
    if publishers == 0:
        if received:
            return (
                f"⚠️ `{topic}` has **no publisher any more**: the last picture stays until "
                "a node publishes again."
            )
        return f"⚠️ `{topic}` has **no publisher**: start a node that publishes it."
    if received == 0:
        return f"⏳ `{topic}` has {publishers} publisher(s); waiting for the first message…"
    if latched:
        return ""
    if seconds_since_last is not None and seconds_since_last > STALE_AFTER_SEC:
        return (
            f"⚠️ `{topic}` **stopped publishing** {seconds_since_last:.0f} s ago "
            f"({publishers} publisher(s) still on the graph)."
        )
    return ""
