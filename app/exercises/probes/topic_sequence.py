"""Probe ``topic_sequence``: consecutive messages follow a rule ("prev + 1")."""

from __future__ import annotations

from app.exercises.probes.base import ProbeContext, draw, expected_value, register_probe, same
from app.exercises.probes.topics import publishers_note, with_note
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros.convert import field_value, import_type, to_plain
from app.ros.monitor import TopicMonitor


@register_probe(
    "topic_sequence",
    feeds=False,
    required="topic type field expect",
    optional="count within tolerance",
    words="reads a random number of consecutive messages; each one's field must follow "
    "from the one before by the exercise's rule",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
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
        return Result(name, False, with_note(text, publishers_note(node, topic, type_text)))
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
