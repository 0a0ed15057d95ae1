"""QoS in a bag: what each publisher offered, and the profile a replay publishes with.

rosbag2 stores every publisher's offered profile per topic. On replay a
topic whose publishers were all transient-local is published transient-local
again (so a late subscriber still gets the latched message), and reliable
when they were all reliable; depth comes from the recording.
"""

from __future__ import annotations

from rclpy.duration import Duration
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSProfile,
    ReliabilityPolicy,
)
from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)

# Replaying volatile topics keeps at least this many: a fast bag must not be
# throttled by a tutorial publisher's depth of 10.
MIN_REPLAY_DEPTH = 100
# rmw's "infinite" durations, as rosbag2 writes them.
_INFINITE = QosTime(2147483647, 4294967295)


def _time(duration: Duration) -> QosTime:
    nanos = duration.nanoseconds
    if nanos <= 0 or nanos >= 2**63 - 1:
        return _INFINITE if nanos else QosTime(0, 0)
    return QosTime(nanos // 1_000_000_000, nanos % 1_000_000_000)


def _enum(target: type, value: object, unknown: object) -> object:
    name = getattr(value, "name", "").upper()
    return target.__members__.get(name, unknown)  # type: ignore[attr-defined]


def to_bag(profile: QoSProfile) -> Qos:
    """A publisher's offered profile (from the graph) as rosbags stores it."""
    return Qos(
        history=_enum(QosHistory, profile.history, QosHistory.UNKNOWN),  # type: ignore[arg-type]
        depth=int(profile.depth),
        reliability=_enum(QosReliability, profile.reliability, QosReliability.UNKNOWN),  # type: ignore[arg-type]
        durability=_enum(QosDurability, profile.durability, QosDurability.UNKNOWN),  # type: ignore[arg-type]
        deadline=_time(profile.deadline),
        lifespan=_time(profile.lifespan),
        liveliness=_enum(QosLiveliness, profile.liveliness, QosLiveliness.UNKNOWN),  # type: ignore[arg-type]
        liveliness_lease_duration=_time(profile.liveliness_lease_duration),
        avoid_ros_namespace_conventions=bool(profile.avoid_ros_namespace_conventions),
    )


def replay_profile(offered: list[Qos]) -> QoSProfile:
    """The profile a replay publisher uses, from the profiles recorded for its topic."""
    reliable = bool(offered) and all(q.reliability == QosReliability.RELIABLE for q in offered)
    latched = bool(offered) and all(q.durability == QosDurability.TRANSIENT_LOCAL for q in offered)
    depths = [q.depth for q in offered if q.history == QosHistory.KEEP_LAST and q.depth > 0]
    depth = max(depths, default=10)
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        # Latched topics keep exactly what the original kept for late joiners.
        depth=depth if latched else max(depth, MIN_REPLAY_DEPTH),
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
        liveliness=LivelinessPolicy.AUTOMATIC,
    )


def describe(offered: list[Qos]) -> str:
    """'reliable, transient_local' for info lines; 'unknown' when nothing was recorded."""
    if not offered:
        return "unknown"
    q = replay_profile(offered)
    return f"{q.reliability.name.lower()}, {q.durability.name.lower()}"
