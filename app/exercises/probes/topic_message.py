"""Probe ``topic_message``: a message's fields equal the expected ones, optionally read by a
subscriber that joins late and asks for transient-local history.
"""

from __future__ import annotations

from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from app.exercises.probes.base import ProbeContext, register_probe
from app.exercises.probes.topics import difference, publishers_note, with_note
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros.convert import import_type, to_plain
from app.ros.monitor import TopicMonitor


@register_probe(
    "topic_message",
    feeds=False,
    required="topic type expect",
    optional="within delay durability tolerance",
    words="subscribes (late, asking for the kept history, when durability is transient_local) "
    "and compares the fields of a message with the expected ones",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
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
        note = publishers_note(node, topic, type_text, durability)
        return Result(name, False, with_note(text, note))
    got = to_plain(newest[1])
    wrong = difference(got, p["expect"], p.get("tolerance", 1e-6), "")
    if wrong:
        return Result(name, False, f"in the message on {topic}: {wrong}")
    fields = ", ".join(sorted(p["expect"]))
    return Result(name, True, f"{topic} carried the expected {fields}")
