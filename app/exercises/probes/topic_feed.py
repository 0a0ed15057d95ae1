"""Probe ``topic_feed``: publish drawn values, compare the node's outputs to a formula."""

from __future__ import annotations

import time
from collections.abc import Sequence

from rclpy.qos import QoSProfile

from app.exercises.probes.base import ProbeContext, draw, expected_value, register_probe, same
from app.exercises.probes.topics import others_subscribed, wait_answering
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros.convert import fill, import_type, to_plain
from app.ros.monitor import TopicMonitor

LOST_AT_START = 2  # answers to the first inputs that may not reach us (see run)


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
        passed, detail = judge(inputs, in_topic, out_topic, got, want, p.get("tolerance", 1e-6))
        return Result(name, passed, detail)
    finally:
        monitor.close()
        node.destroy_publisher(publisher)


def judge(
    inputs: Sequence[object],
    in_topic: str,
    out_topic: str,
    got: Sequence[object],
    want: Sequence[object],
    tolerance: float,
) -> tuple[bool, str]:
    """Whether the answers ``got`` are the formula's ``want``, and the result's words.

    The answers line up with the last inputs. The first ones may not have come: the
    node's writer can match our reader a moment after the graph shows it (a restarted
    node: its last run's writer is still matched), so the node answered before we could
    hear it. Up to LOST_AT_START of them may be missing.
    """
    lost = max(0, len(want) - len(got))
    if not got or lost > LOST_AT_START:
        return (
            False,
            f"published {inputs} on {in_topic}; {out_topic} gave {got}, expected {want}",
        )
    tail, wanted = got[-(len(want) - lost) :], want[lost:]
    wrong = [
        i for i, (a, b) in enumerate(zip(tail, wanted, strict=True)) if not same(a, b, tolerance)
    ]
    first = "the first answer" if lost == 1 else f"the first {lost} answers"
    unheard = f" ({first} did not reach the grader)" if lost else ""
    if not wrong:
        return True, f"published {inputs}; {out_topic} gave {tail}{unheard}"
    at = wrong[0]
    return False, (
        f"published {inputs} on {in_topic}; {out_topic} gave {tail}, expected {want} "
        f"(first difference at message {lost + at + 1}: {tail[at]!r}, "
        f"expected {wanted[at]!r}){unheard}"
    )
