"""Probe ``message_feed``: messages with drawn fields go in; each answer's fields must follow
from its input by the exercise's formulas.

``inputs`` gives the input message's fields (ranges and word lists are drawn,
nested tables for nested messages); ``expect`` gives the answer's fields that
matter, each a formula over the input's fields (``"18.0 / z"``, ``"'camera'"``),
nested as in the message. Read live (volatile), every input gets its answer in
turn; read as a late joiner (``durability = "transient_local"``), all inputs
go out, and a subscriber that joins ``delay`` s later must get the answer to
the newest one from the topic's kept history.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from app.exercises.probes.base import (
    ProbeContext,
    draw,
    expected_value,
    register_probe,
    values_text,
)
from app.exercises.probes.topics import (
    ANSWER_WAIT_SEC,
    RESENDS,
    SEND_QOS,
    difference,
    listen,
    publishers_note,
    wait_subscribed,
    with_note,
)
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros.convert import fill, import_type, to_plain
from app.ros.monitor import TopicMonitor

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    from rclpy.publisher import Publisher

    from app.exercises.probes.topics import M

LATE_QOS = QoSProfile(
    depth=10, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


def expected_fields(expect: object, names: Mapping[str, object]) -> object:
    """The answer's fields: each formula of ``expect`` evaluated on the input's fields."""
    if isinstance(expect, dict):
        return {key: expected_fields(value, names) for key, value in expect.items()}
    if isinstance(expect, str):
        return expected_value(expect, names)
    return expect


@register_probe(
    "message_feed",
    required="publish type inputs output output_type expect",
    optional="durability delay within tolerance period",
    defaults={"count": [3, 5]},
    words="publishes messages with random fields to the node; each answer's fields must follow "
    "from its input by the exercise's formulas (read by a subscriber that joins late, when "
    "durability is transient_local)",
    draws="the input messages' fields (inputs), and how many are sent (count)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    node = ctx.call.node
    in_topic, out_topic = p["publish"], p["output"]
    in_type, out_type = import_type(p["type"], "msg"), import_type(p["output_type"], "msg")
    durability = p.get("durability", "volatile")
    if durability not in ("volatile", "transient_local"):
        raise ValueError(f"durability must be volatile or transient_local, not {durability!r}")
    late = durability == "transient_local"
    name = f"feed {in_topic} -> {out_topic}" + (" (late joiner)" if late else "")
    inputs = [draw(ctx.rng, p["inputs"]) for _ in range(int(draw(ctx.rng, p["count"])))]
    tolerance = float(p.get("tolerance", 1e-6))
    publisher = node.create_publisher(in_type, in_topic, SEND_QOS)
    monitor = None if late else listen(ctx, out_topic, out_type)
    try:
        why = wait_subscribed(ctx, publisher, in_topic)
        if why:
            return Result(name, False, why)
        if late:
            return _late_joiner(ctx, p, publisher, inputs, name, tolerance)
        assert monitor is not None
        previous: object = None
        for index, values in enumerate(inputs, start=1):
            want = expected_fields(p["expect"], values)
            answer = _answer(ctx, publisher, monitor, fill(in_type, values), want, previous, p)
            sent = f"sent {values_text(values)} on {in_topic}"
            if answer is None:
                note = publishers_note(node, out_topic, p["output_type"])
                text = f"{sent} (message {index}); nothing came back on {out_topic}"
                return Result(name, False, with_note(text, note))
            wrong = difference(to_plain(answer), want, tolerance, "")
            if wrong:
                return Result(name, False, f"{sent}: in the answer on {out_topic}, {wrong}")
            previous = want
        fields = ", ".join(sorted(p["expect"]))
        return Result(
            name, True, f"{len(inputs)} random messages, each answered with the right {fields}"
        )
    finally:
        if monitor is not None:
            monitor.close()
        node.destroy_publisher(publisher)


def _answer(
    ctx: ProbeContext,
    publisher: Publisher,
    monitor: TopicMonitor[M],
    message: object,
    want: object,
    previous: object,
    p: Spec,
) -> M | None:
    """The node's answer to ``message``, sent again when nothing comes (discovery may lag).

    A late second answer to the previous input (it was sent twice) is skipped.
    """
    seen = monitor.count
    tolerance = float(p.get("tolerance", 1e-6))
    wait = float(p.get("within", ANSWER_WAIT_SEC))
    for _ in range(RESENDS):
        publisher.publish(message)
        deadline = time.monotonic() + wait
        while time.monotonic() < deadline:
            monitor.wait_for_count(seen + 1, 0.1)
            ctx.call.check_cancel()
            for _arrival, answer in monitor.messages_since(seen):
                seen += 1
                plain = to_plain(answer)
                is_old = previous is not None and not difference(plain, previous, tolerance, "")
                if is_old and difference(plain, want, tolerance, ""):
                    continue
                return answer
    return None


def _late_joiner(
    ctx: ProbeContext,
    p: Spec,
    publisher: Publisher,
    inputs: Sequence[Mapping[str, object]],
    name: str,
    tolerance: float,
) -> Result:
    """Send every input, wait, then join late: the kept answer must be the newest input's."""
    node = ctx.call.node
    in_type, out_type = import_type(p["type"], "msg"), import_type(p["output_type"], "msg")
    out_topic = p["output"]
    for values in inputs:
        publisher.publish(fill(in_type, values))
        ctx.call.sleep(float(p.get("period", 0.2)))
    ctx.call.sleep(float(p.get("delay", 1.0)))  # sent and answered by now; the reader joins late
    monitor = TopicMonitor(node, out_topic, out_type, keep=10, qos=LATE_QOS)
    within = float(p.get("within", 4.0))
    try:
        monitor.wait_for_count(1, within)
        deadline = time.monotonic() + 0.5  # the rest of the kept history, if any
        while time.monotonic() < deadline:
            ctx.call.sleep(0.1)
        newest = monitor.message(1)
    finally:
        monitor.close()
    sent = "sent " + "; ".join(values_text(v) for v in inputs) + f" on {p['publish']}"
    if newest is None:
        text = (
            f"{sent}; a subscriber that joined {out_topic} later and asked for the kept "
            f"history got nothing within {within:g} s"
        )
        return Result(
            name,
            False,
            with_note(text, publishers_note(node, out_topic, p["output_type"], "transient_local")),
        )
    want = expected_fields(p["expect"], inputs[-1])
    wrong = difference(to_plain(newest[1]), want, tolerance, "")
    if wrong:
        return Result(
            name,
            False,
            f"{sent}; a subscriber that joined later got, as the newest message, {wrong}",
        )
    return Result(name, True, f"{sent}; a subscriber that joined later got the newest answer")
