"""Probes that judge what a node publishes and how: sequences, message fields, QoS.

- ``topic_sequence``: consecutive messages follow a rule ("prev + 1");
- ``topic_message``: a message's fields equal the expected ones, optionally
  read by a subscriber that joins late and asks for transient-local history;
- ``qos_match``: the learner's subscription can be served by the topic's
  publishers (a reliable subscription cannot use a best-effort publisher).
"""

from __future__ import annotations

import time
from typing import Any

from rclpy.node import Node
from rclpy.qos import (
    DurabilityPolicy,
    QoSCompatibility,
    QoSProfile,
    ReliabilityPolicy,
    qos_check_compatible,
)

from app.exercises.probes.base import Probe, ProbeContext, draw, expected_value, same
from app.exercises.report import Result
from app.lessons.kinds import Kind, make_kind
from app.lessons.schema import Spec
from app.ros.convert import field_value, import_type, to_plain
from app.ros.monitor import TopicMonitor
from app.ros.names import node_fqn

GRAPH_WAIT_SEC = 3.0  # a fresh subscription needs a moment to show on the graph


def _profile_text(qos: QoSProfile) -> str:
    """'best_effort, volatile' for a profile."""
    return f"{qos.reliability.name.lower()}, {qos.durability.name.lower()}"


def _publishers_note(node: Node, topic: str, type_text: str, durability: str = "") -> str:
    """Why nothing may have arrived: no publisher, another type, or volatile history."""
    infos = node.get_publishers_info_by_topic(topic)
    if not infos:
        return f"nothing publishes on {topic}"
    types = sorted({info.topic_type for info in infos})
    if type_text not in types:
        return f"{topic} is published as {', '.join(types)}, not {type_text}"
    if durability == "transient_local":
        volatile = [
            node_fqn(i.node_name, i.node_namespace)
            for i in infos
            if i.qos_profile.durability != DurabilityPolicy.TRANSIENT_LOCAL
        ]
        if volatile:
            return (
                f"{', '.join(volatile)} publishes with volatile durability: it keeps nothing "
                "for a subscriber that joins later"
            )
    return ""


def _with_note(text: str, note: str) -> str:
    return f"{text} ({note})" if note else text


# -- topic_sequence ----------------------------------------------------------


def topic_sequence(ctx: ProbeContext, p: Spec) -> Result:
    """Read ``count`` messages; each one's field must follow from the one before."""
    node = ctx.call.node
    topic, type_text, field = p["topic"], p["type"], p["field"]
    count, within = int(draw(ctx.rng, p.get("count", 5))), p.get("within", 5.0)
    name = f"sequence on {topic}"
    # As `ros2 topic echo`: match the publishers' QoS, so a reliable stream is read reliably.
    monitor = TopicMonitor(node, topic, import_type(type_text, "msg"), keep=count)
    try:
        monitor.wait_for_count(count, within)
        values = [to_plain(field_value(msg, field)) for _, msg in monitor.recent()]
    finally:
        monitor.close()
    if len(values) < 2:
        text = f"{len(values)} messages on {topic} in {within:g} s, needed {count}"
        return Result(name, False, _with_note(text, _publishers_note(node, topic, type_text)))
    tolerance = p.get("tolerance", 1e-6)
    for prev, value in zip(values, values[1:], strict=False):
        want = expected_value(p["expect"], {"prev": prev})
        if not same(value, want, tolerance):
            return Result(
                name,
                False,
                f"{topic} gave {field} = {values}: after {prev!r} came {value!r}, "
                f"expected {want!r} ({p['expect']})",
            )
    return Result(name, True, f"{topic} gave {field} = {values}")


# -- topic_message -----------------------------------------------------------


def _difference(actual: Any, expected: Any, tolerance: float, path: str) -> str:
    """'' when ``actual`` has every expected field (deeply), else the first that differs."""
    if isinstance(expected, dict):
        if not isinstance(actual, dict):
            return f"{path} = {actual!r}, expected {expected!r}"
        for key, want in expected.items():
            where = f"{path}.{key}" if path else key
            if key not in actual:
                return f"the message has no field {where}"
            found = _difference(actual[key], want, tolerance, where)
            if found:
                return found
        return ""
    if same(actual, expected, tolerance):
        return ""
    return f"{path} = {actual!r}, expected {expected!r}"


def topic_message(ctx: ProbeContext, p: Spec) -> Result:
    """Subscribe (after ``delay`` s, with the given durability) and compare one message.

    ``expect`` lists only the fields that matter, nested as in the message:
    ``{ label = "red_ball", position_in_camera = { x = 0.5 } }``.
    """
    node = ctx.call.node
    topic, type_text = p["topic"], p["type"]
    durability = p.get("durability", "volatile")
    within = p.get("within", 4.0)
    late = durability == "transient_local"
    name = f"message on {topic}" + (" (late joiner)" if late else "")
    if durability not in ("volatile", "transient_local"):
        raise ValueError(f"durability must be volatile or transient_local, not {durability!r}")
    ctx.call.sleep(p.get("delay", 0.0))
    qos = QoSProfile(
        depth=10,
        # A late joiner asks for what a latched topic offers; otherwise hear any publisher.
        reliability=ReliabilityPolicy.RELIABLE if late else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if late else DurabilityPolicy.VOLATILE,
    )
    monitor = TopicMonitor(node, topic, import_type(type_text, "msg"), keep=10, qos=qos)
    try:
        monitor.wait_for_count(1, within)
        newest = monitor.message(1)
    finally:
        monitor.close()
    if newest is None:
        how = "a subscriber that joined late and asked for transient-local history got "
        text = f"{how if late else ''}no message on {topic} within {within:g} s"
        note = _publishers_note(node, topic, type_text, durability)
        return Result(name, False, _with_note(text, note))
    got = to_plain(newest[1])
    difference = _difference(got, p["expect"], p.get("tolerance", 1e-6), "")
    if difference:
        return Result(name, False, f"in the message on {topic}: {difference}")
    fields = ", ".join(sorted(p["expect"]))
    return Result(name, True, f"{topic} carried the expected {fields}")


# -- qos_match ---------------------------------------------------------------


def qos_match(ctx: ProbeContext, p: Spec) -> Result:
    """The learner's subscription on ``topic`` must be compatible with every publisher."""
    node = ctx.call.node
    topic, target = p["topic"], p.get("node", ctx.learner_node)
    name = f"QoS on {topic}"
    own = node_fqn(node.get_name(), node.get_namespace())
    deadline = time.monotonic() + GRAPH_WAIT_SEC
    while True:
        subs = [
            info
            for info in node.get_subscriptions_info_by_topic(topic)
            if node_fqn(info.node_name, info.node_namespace) == target
        ]
        pubs = [
            info
            for info in node.get_publishers_info_by_topic(topic)
            if node_fqn(info.node_name, info.node_namespace) != own
        ]
        if (subs and pubs) or time.monotonic() > deadline:
            break
        ctx.call.sleep(0.2)
    if not subs:
        return Result(name, False, f"{target} has no subscription on {topic}")
    if not pubs:
        return Result(name, False, f"nothing publishes on {topic}")
    for sub in subs:
        for pub in pubs:
            publisher = node_fqn(pub.node_name, pub.node_namespace)
            compatibility, reason = qos_check_compatible(pub.qos_profile, sub.qos_profile)
            if compatibility == QoSCompatibility.ERROR:
                return Result(
                    name,
                    False,
                    f"{target} requests {_profile_text(sub.qos_profile)} on {topic}, but "
                    f"{publisher} offers {_profile_text(pub.qos_profile)}: incompatible, "
                    f"nothing is delivered ({reason.strip()})",
                )
    offered = ", ".join(
        f"{node_fqn(i.node_name, i.node_namespace)} ({_profile_text(i.qos_profile)})" for i in pubs
    )
    return Result(
        name,
        True,
        f"{target} requests {_profile_text(subs[0].qos_profile)}: compatible with {offered}",
    )


# Each kind's fields (the loader validates against them) and its code.
KINDS: dict[str, Kind] = {
    "topic_sequence": make_kind("topic type field expect", "count within tolerance"),
    "topic_message": make_kind("topic type expect", "within delay durability tolerance"),
    "qos_match": make_kind("topic", "node"),
}
PROBES: dict[str, Probe] = {
    "topic_sequence": topic_sequence,
    "topic_message": topic_message,
    "qos_match": qos_match,
}
