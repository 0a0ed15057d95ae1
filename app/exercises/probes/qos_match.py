"""Probe ``qos_match``: the learner's subscription can be served by the topic's publishers
(a reliable subscription cannot use a best-effort publisher).
"""

from __future__ import annotations

import time

from rclpy.qos import QoSCompatibility, qos_check_compatible

from app.exercises.probes.base import ProbeContext, register_probe
from app.exercises.probes.topics import profile_text
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros.names import node_fqn

GRAPH_WAIT_SEC = 3.0  # a fresh subscription needs a moment to show on the graph


@register_probe(
    "qos_match",
    feeds=False,
    required="topic",
    optional="node",
    words="the node's subscription on the topic must be compatible with the QoS every "
    "publisher offers",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
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
                    f"{target} requests {profile_text(sub.qos_profile)} on {topic}, but "
                    f"{publisher} offers {profile_text(pub.qos_profile)}: incompatible, "
                    f"nothing is delivered ({reason.strip()})",
                )
    offered = ", ".join(
        f"{node_fqn(i.node_name, i.node_namespace)} ({profile_text(i.qos_profile)})" for i in pubs
    )
    return Result(
        name,
        True,
        f"{target} requests {profile_text(subs[0].qos_profile)}: compatible with {offered}",
    )
