"""QoS: choosing a subscription that matches the publishers, and printing a profile."""

from __future__ import annotations

from typing import Any

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

# Measuring (hz, bw, rates) subscribes best effort: it must never slow a
# reliable publisher, and it hears best-effort and reliable ones alike.
MEASURE_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=100,
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
)


def matching_qos(node: Node, topic: str, depth: int = 10) -> QoSProfile:
    """A subscription QoS every current publisher is compatible with (as ros2 echo picks it)."""
    publishers = node.get_publishers_info_by_topic(topic)
    reliable = bool(publishers) and all(
        p.qos_profile.reliability == ReliabilityPolicy.RELIABLE for p in publishers
    )
    transient = bool(publishers) and all(
        p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in publishers
    )
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=depth,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if transient else DurabilityPolicy.VOLATILE,
    )


def qos_lines(qos: QoSProfile) -> list[str]:
    """A profile as `ros2 topic info -v` prints it."""

    def policy(value: Any) -> str:
        return getattr(value, "name", str(value)).upper()

    def duration(value: Any) -> str:
        nanos = getattr(value, "nanoseconds", 0)
        return "Infinite" if nanos == 0 or nanos >= 2**63 - 1 else f"{nanos} nanoseconds"

    depth = "UNKNOWN" if qos.history != HistoryPolicy.KEEP_LAST else str(qos.depth)
    return [
        "QoS profile:",
        f"  Reliability: {policy(qos.reliability)}",
        f"  History (Depth): {policy(qos.history)} ({depth})",
        f"  Durability: {policy(qos.durability)}",
        f"  Lifespan: {duration(qos.lifespan)}",
        f"  Deadline: {duration(qos.deadline)}",
        f"  Liveliness: {policy(qos.liveliness)}",
        f"  Liveliness lease duration: {duration(qos.liveliness_lease_duration)}",
    ]
