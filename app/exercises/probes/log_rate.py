"""Probe ``log_rate``: how often does the node log? Judged by its own log stamps."""

from __future__ import annotations

import threading

from app.exercises.probes.base import ProbeContext, register_probe
from app.exercises.report import Result
from app.lessons.schema import Spec

LOG_RATE_MIN_LINES = 6  # fewer is no rate to judge on


@register_probe(
    "log_rate",
    required="min_hz max_hz",
    optional="node text window",
    words="counts the node's log lines on /rosout over a window and judges their rate by "
    "the node's own log stamps",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    from rcl_interfaces.msg import Log

    target = p.get("node", ctx.learner_node)
    logger = target.lstrip("/").replace("/", ".")
    text = p.get("text", "")
    stamps: list[float] = []
    lock = threading.Lock()

    def on_log(record: Log) -> None:
        if record.name == logger and text in record.msg:
            with lock:
                stamps.append(record.stamp.sec + record.stamp.nanosec * 1e-9)

    node = ctx.call.node
    sub = node.create_subscription(Log, "/rosout", on_log, 100)
    try:
        ctx.call.sleep(p.get("window", 5.0))
    finally:
        node.destroy_subscription(sub)
    name = f"log rate of {target}"
    with lock:
        got = sorted(stamps)
    what = f"lines containing {text!r}" if text else "log lines"
    if len(got) < LOG_RATE_MIN_LINES or got[-1] <= got[0]:
        return Result(name, False, f"{len(got)} {what} from {target} in {p.get('window', 5.0):g} s")
    # By the node's own log stamps (its clock), so late delivery does not bend the rate.
    rate = (len(got) - 1) / (got[-1] - got[0])
    measured = f"{rate:.2f} Hz over {len(got)} lines (the node's log stamps)"
    if p["min_hz"] <= rate <= p["max_hz"]:
        return Result(name, True, f"{target} logs {what} at {measured}")
    return Result(
        name,
        False,
        f"{target} logs {what} at {measured}; expected {p['min_hz']}-{p['max_hz']} Hz",
    )
