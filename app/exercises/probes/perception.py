"""Probes for the later units: graph resources, images, frames and point clouds.

Each one feeds the learner's node data whose right answer the probe knows
(synthetic images, random points, a depth scene), reads what comes back and
says in numbers what differs: "IoU 0.42 on image 2", "x and y look swapped".
Inputs are built here with numpy, never taken from a catalog node, so a
grade does not depend on timing or on what else runs.
"""

from __future__ import annotations

import time
from typing import Any

from rclpy.qos import QoSProfile, ReliabilityPolicy

from app.exercises.probes.base import Probe, ProbeContext
from app.exercises.report import Result
from app.lessons.kinds import make_kind
from app.lessons.schema import Spec
from app.ros.monitor import TopicMonitor

# Hears reliable and best-effort publishers alike.
LISTEN_QOS = QoSProfile(depth=20, reliability=ReliabilityPolicy.BEST_EFFORT)
# Reaches reliable and best-effort subscribers alike.
SEND_QOS = QoSProfile(depth=10)
MATCH_WAIT_SEC = 5.0  # for the learner's subscription to appear
ANSWER_WAIT_SEC = 2.0  # for one answer to one input
RESENDS = 3  # an input is sent again when no answer came (discovery may lag)


# -- shared helpers ----------------------------------------------------------


def _split_name(fqn: str) -> tuple[str, str]:
    namespace, _, name = fqn.rpartition("/")
    return namespace or "/", name


def _wait_subscribed(ctx: ProbeContext, publisher: Any, topic: str) -> str:
    """'' once someone subscribes to ``topic``, else why not."""
    deadline = time.monotonic() + MATCH_WAIT_SEC
    while publisher.get_subscription_count() == 0:
        if time.monotonic() > deadline:
            return f"nothing subscribes to {topic} (waited {MATCH_WAIT_SEC:g} s)"
        ctx.call.sleep(0.05)
    ctx.call.sleep(0.3)  # let the learner's publisher find our reader too
    return ""


def _exchange(
    ctx: ProbeContext,
    publisher: Any,
    monitor: TopicMonitor,
    message: Any,
    stamp_sec: int,
    known_stamps: set[int],
) -> Any | None:
    """Send ``message`` (stamped ``stamp_sec``) and return the answer to it, or None.

    An answer that carries the stamp of our input belongs to it; one with a
    stamp we never sent (another publisher's input) is ignored; one with a
    zero stamp (the node did not copy the header) is taken as the answer to
    the newest input.
    """
    message.header.stamp.sec, message.header.stamp.nanosec = stamp_sec, 0
    seen = monitor.count
    for _ in range(RESENDS):
        publisher.publish(message)
        deadline = time.monotonic() + ANSWER_WAIT_SEC
        while time.monotonic() < deadline:
            monitor.wait_for_count(seen + 1, 0.1)
            ctx.call.check_cancel()
            for _arrival, answer in monitor.messages_since(seen):
                seen += 1
                got = int(answer.header.stamp.sec)
                if got == stamp_sec or (got == 0 and answer.header.stamp.nanosec == 0):
                    return answer
                if got in known_stamps:
                    continue  # a late answer to an earlier input
    return None


def _fmt(values: Any) -> str:
    return "(" + ", ".join(f"{float(v):.3f}" for v in values) + ")"


# -- publisher_count ---------------------------------------------------------


def publisher_count(ctx: ProbeContext, p: Spec) -> Result:
    """How many publishers the node has on a topic (e.g. none left after cleanup)."""
    target = p.get("node", ctx.learner_node)
    topic, want = p["topic"], p["count"]
    namespace, name = _split_name(target)
    after = f" after {p['after']}" if "after" in p.fields else ""
    deadline = time.monotonic() + p.get("within", 3.0)
    while True:
        got = sum(
            1
            for info in ctx.call.node.get_publishers_info_by_topic(topic)
            if info.node_name == name and info.node_namespace == namespace
        )
        if got == want:
            return Result(
                f"publishers of {target}",
                True,
                f"{target} has {got} publisher(s) on {topic}{after}, as expected",
            )
        if time.monotonic() > deadline:
            return Result(
                f"publishers of {target}",
                False,
                f"{target} has {got} publisher(s) on {topic}{after}; expected {want}",
            )
        ctx.call.sleep(0.2)


# Each kind's fields (the loader validates against them) and its code.
KINDS = {
    "publisher_count": make_kind("topic count", "node after within"),
}
PROBES: dict[str, Probe] = {
    "publisher_count": publisher_count,
}
