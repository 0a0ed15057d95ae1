"""qos_settings: turn the QoS parameter values of qos_talker/qos_listener into a profile.

Not a node: a small helper both QoS nodes share. ``declare_qos_parameters``
declares the three read-only parameters on a node and returns their profile;
the rest keeps no ROS state, so it can be tested on its own.

A ``QoSProfile`` bundles the policies a publisher offers or a subscriber
requests. The two taught here:

- reliability: ``reliable`` (lost samples are re-sent) or ``best_effort``
  (fire and forget, as sensor streams often are);
- durability: ``volatile`` (late joiners get only new messages) or
  ``transient_local`` (the publisher keeps its last ``depth`` messages and
  hands them to subscribers that join later).

A connection is made only when what the publisher offers is at least what the
subscriber requests: a reliable subscriber cannot use a best-effort
publisher, and a transient-local subscriber cannot use a volatile one. Every
other combination works.
"""

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

RELIABILITY = {"reliable": ReliabilityPolicy.RELIABLE, "best_effort": ReliabilityPolicy.BEST_EFFORT}
DURABILITY = {
    "volatile": DurabilityPolicy.VOLATILE,
    "transient_local": DurabilityPolicy.TRANSIENT_LOCAL,
}


def profile_from_names(reliability: str, durability: str, depth: int) -> QoSProfile:
    """A keep-last profile from parameter values; ValueError names the bad one."""
    if reliability not in RELIABILITY:
        raise ValueError(f"reliability must be one of {sorted(RELIABILITY)}, got {reliability!r}")
    if durability not in DURABILITY:
        raise ValueError(f"durability must be one of {sorted(DURABILITY)}, got {durability!r}")
    if depth < 1:
        raise ValueError(f"depth must be at least 1, got {depth}")
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=depth,
        reliability=RELIABILITY[reliability],
        durability=DURABILITY[durability],
    )


def describe(profile: QoSProfile) -> str:
    """E.g. 'reliable, transient_local, depth 10'."""
    reliability = {v: k for k, v in RELIABILITY.items()}[profile.reliability]
    durability = {v: k for k, v in DURABILITY.items()}[profile.durability]
    return f"{reliability}, {durability}, depth {profile.depth}"


def declare_qos_parameters(node: Node) -> QoSProfile:
    """Declare ``reliability``, ``durability`` and ``depth`` on ``node``; their profile.

    Read-only: QoS is fixed when a publisher or subscription is created, so a
    change later could not take effect (``--ros-args -p`` still sets them at
    start-up). ValueError names a value that is not understood.
    """
    read_only = ParameterDescriptor(read_only=True, description="fixed at start-up")
    reliability = node.declare_parameter("reliability", "reliable", read_only).value
    durability = node.declare_parameter("durability", "volatile", read_only).value
    depth = node.declare_parameter("depth", 10, read_only).value
    return profile_from_names(reliability, durability, depth)
