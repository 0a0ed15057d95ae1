"""Probe ``topic_feed``: publish drawn values, compare the node's outputs to a formula."""

from __future__ import annotations

import time

from rclpy.qos import QoSProfile

from app.exercises.probes.base import ProbeContext, draw, expected_value, register_probe, same
from app.exercises.probes.topics import others_subscribed, wait_answering
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros.convert import fill, import_type, to_plain
from app.ros.monitor import TopicMonitor


@register_probe(
    "topic_feed",
    required="publish type input_field inputs count output output_type field expect",
    optional="period settle tolerance",
    words="publishes random values to the node and compares what it publishes back to the "
    "exercise's formula",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    """Publish ``count`` values drawn from ``inputs``; compare the node's outputs to a formula.

    ``expect`` is a formula over ``values`` (the drawn list) giving the list
    of outputs, e.g. the running sums ``[sum(values[: i + 1]) for i in range(len(values))]``.
    """
    node = ctx.call.node
    in_topic, out_topic = p["publish"], p["output"]
    name = f"feed {in_topic} -> {out_topic}"
    in_type, out_type = import_type(p["type"], "msg"), import_type(p["output_type"], "msg")
    count = int(draw(ctx.rng, p["count"]))
    inputs = [draw(ctx.rng, p["inputs"]) for _ in range(count)]
    want = list(expected_value(p["expect"], {"values": inputs}))
    publisher = node.create_publisher(in_type, in_topic, QoSProfile(depth=50))
    monitor = TopicMonitor(node, out_topic, out_type, keep=200, qos=50)
    try:
        deadline = time.monotonic() + 5.0
        while not others_subscribed(node, publisher, in_topic):
            if time.monotonic() > deadline:
                return Result(name, False, f"nothing subscribes to {in_topic}")
            ctx.call.sleep(0.05)
        wait_answering(ctx, monitor)  # else its first answers can be lost
        before = monitor.count
        for value in inputs:
            publisher.publish(fill(in_type, {p["input_field"]: value}))
            ctx.call.sleep(p.get("period", 0.15))
        monitor.wait_for_count(before + len(want), p.get("settle", 2.0))
        field = p["field"]
        got = [to_plain(getattr(msg, field)) for _, msg in monitor.messages_since(before)]
        if len(got) < len(want):
            return Result(
                name,
                False,
                f"published {inputs} on {in_topic}; {out_topic} gave {got}, expected {want}",
            )
        tail = got[-len(want) :]
        tolerance = p.get("tolerance", 1e-6)
        wrong = [
            i for i, (a, b) in enumerate(zip(tail, want, strict=True)) if not same(a, b, tolerance)
        ]
        if not wrong:
            return Result(name, True, f"published {inputs}; {out_topic} gave {tail}")
        return Result(
            name,
            False,
            f"published {inputs} on {in_topic}; {out_topic} gave {tail}, expected {want} "
            f"(first difference at message {wrong[0] + 1}: {tail[wrong[0]]!r}, "
            f"expected {want[wrong[0]]!r})",
        )
    finally:
        monitor.close()
        node.destroy_publisher(publisher)
