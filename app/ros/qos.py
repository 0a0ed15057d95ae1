"""QoS: choosing a subscription that matches the publishers, printing a profile, and
finding subscribers no publisher can deliver to."""

from __future__ import annotations

from collections.abc import Sequence

from rclpy.node import Node
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSCompatibility,
    QoSProfile,
    ReliabilityPolicy,
    qos_check_compatible,
)
from rclpy.topic_endpoint_info import TopicEndpointInfo

# Measuring (hz, bw, rates) subscribes best effort: it must never slow a
# reliable publisher, and it hears best-effort and reliable ones alike.
MEASURE_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=100,
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
)


def matching_qos(node: Node, topic: str, depth: int = 10, *, latched: bool = True) -> QoSProfile:
    """A subscription QoS every current publisher is compatible with (as ros2 echo picks it).

    ``latched=False``: volatile even when every publisher keeps its last message
    for late joiners (a view that wants only what is new).
    """
    qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=depth)
    return suit_publishers(qos, node.get_publishers_info_by_topic(topic), latched=latched)


def suit_publishers(
    qos: QoSProfile, publishers: Sequence[TopicEndpointInfo], *, latched: bool = True
) -> QoSProfile:
    """``qos`` made reliable only when every publisher offers reliable delivery (a
    reliable reader cannot hear a best-effort writer), and transient local only when
    every one keeps its last messages for late joiners (a volatile writer cannot
    serve a transient-local reader). No publishers: best effort and volatile."""
    every = bool(publishers)
    reliable = every and all(
        p.qos_profile.reliability == ReliabilityPolicy.RELIABLE for p in publishers
    )
    transient = (
        latched
        and every
        and all(p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in publishers)
    )
    qos.reliability = ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT
    qos.durability = DurabilityPolicy.TRANSIENT_LOCAL if transient else DurabilityPolicy.VOLATILE
    return qos


def qos_lines(qos: QoSProfile) -> list[str]:
    """A profile as `ros2 topic info -v` prints it."""

    def policy(value: object) -> str:
        return str(getattr(value, "name", value)).upper()

    def duration(value: object) -> str:
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


def undelivered(node: Node, topic: str) -> dict[str, str]:
    """The subscribers of ``topic`` (by node, fully qualified) that none of its publishers
    can deliver to, each with why in rclpy's words ("Best effort publisher and reliable
    subscription"); {} while it has no publisher (nothing to deliver is no mismatch)."""
    publishers = node.get_publishers_info_by_topic(topic)
    if not publishers:
        return {}
    out: dict[str, str] = {}
    for sub in node.get_subscriptions_info_by_topic(topic):
        reasons = []
        for pub in publishers:
            compatible, why = qos_check_compatible(pub.qos_profile, sub.qos_profile)
            if compatible != QoSCompatibility.ERROR:
                break
            reasons.append(why.removeprefix("ERROR:").strip().rstrip(";"))
        else:
            if sub.node_name == "_NODE_NAME_UNKNOWN_":  # discovered before its node: next time
                continue
            name = f"{sub.node_namespace.rstrip('/')}/{sub.node_name}"
            out.setdefault(name, reasons[0])
    return out
