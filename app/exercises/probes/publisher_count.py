"""Probe ``publisher_count``: how many publishers the node has on a topic (none left after a
cleanup, say).
"""

from __future__ import annotations

import time

from app.exercises.probes.base import ProbeContext, register_probe
from app.exercises.probes.topics import split_name
from app.exercises.report import Result
from app.lessons.schema import Spec


@register_probe(
    "publisher_count",
    feeds=False,
    required="topic count",
    optional="node after within",
    words="counts the node's publishers on the topic (e.g. one, not two, after a cleanup "
    "and a new configure)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    target = p.get("node", ctx.learner_node)
    topic, want = p["topic"], p["count"]
    namespace, name = split_name(target)
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
