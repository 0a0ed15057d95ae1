"""Probe ``log_rate``: how often does the node log? Judged by its own log stamps."""

from __future__ import annotations

import re
import threading

from app.exercises.probes.base import ProbeContext, register_probe
from app.exercises.report import Result
from app.exercises.trace import Trace, thinned
from app.lessons.schema import Spec
from app.ros.monitor import fitted_rate

LOG_RATE_MIN_LINES = 6  # fewer is no rate to judge on


@register_probe(
    "log_rate",
    feeds=False,
    required="min_hz max_hz",
    optional="node text window numbered",
    words="counts the node's log lines on /rosout over a window and judges their rate by "
    "the node's own log stamps (and, when numbered, that each line's number is one more "
    "than the one before)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    from rcl_interfaces.msg import Log

    target = p.get("node", ctx.learner_node)
    logger = target.lstrip("/").replace("/", ".")
    text = p.get("text", "")
    lines: list[tuple[int, str]] = []  # (the node's log stamp in ns, text)
    lock = threading.Lock()

    def on_log(record: Log) -> None:
        if record.name == logger and text in record.msg:
            with lock:
                lines.append((record.stamp.sec * 1_000_000_000 + record.stamp.nanosec, record.msg))

    node = ctx.call.node
    sub = node.create_subscription(Log, "/rosout", on_log, 100)
    try:
        ctx.call.sleep(p.get("window", 5.0))
    finally:
        node.destroy_subscription(sub)
    name = f"log rate of {target}"
    with lock:
        got = [stamp for stamp, _ in sorted(lines)]
        texts = [msg for _, msg in sorted(lines)]
    what = f"lines containing {text!r}" if text else "log lines"
    if len(got) < LOG_RATE_MIN_LINES or got[-1] <= got[0]:
        return Result(name, False, f"{len(got)} {what} from {target} in {p.get('window', 5.0):g} s")
    # By the node's own log stamps (its clock), so late delivery does not bend the rate;
    # a line fitted through all of them, so one line logged late at an end does not either.
    rate = fitted_rate(list(enumerate(got))) or (len(got) - 1) / ((got[-1] - got[0]) * 1e-9)
    measured = f"{rate:.2f} Hz over {len(got)} lines (the node's log stamps)"
    if p.get("numbered", False):
        skipped = _numbering_slip(texts, text)
        if skipped:
            return Result(name, False, f"{target} logs {what}, but {skipped}")
    low, high = float(p["min_hz"]), float(p["max_hz"])
    passed = low <= rate <= high
    trace = Trace.of(
        f"rate of {target}'s {what}, line by line (fitted: {rate:.2f} Hz)",
        "Hz",
        thinned(_line_rates(got)),
        low=low,
        high=high,
        broken_at=None if passed else (got[-1] - got[0]) * 1e-9,
        broken_why="" if passed else f"{rate:.2f} Hz fitted",
        along="time by the node's log stamps (s)",
    )
    if passed:
        return Result(name, True, f"{target} logs {what} at {measured}", (trace,))
    return Result(
        name,
        False,
        f"{target} logs {what} at {measured}; expected {p['min_hz']}-{p['max_hz']} Hz",
        (trace,),
    )


def _line_rates(stamps: list[int]) -> list[tuple[float, float]]:
    """``(time since the first line, 1 / the gap to the line before)`` for each later line."""
    first = stamps[0]
    return [
        ((now - first) * 1e-9, 1e9 / (now - before))
        for before, now in zip(stamps, stamps[1:], strict=False)
        if now > before
    ]


def _numbering_slip(texts: list[str], text: str) -> str:
    """'' when each line's number (the first after ``text``) is one more than the last one's."""
    numbers = []
    for line in texts:
        found = re.search(r"-?\d+", line.split(text, 1)[1] if text else line)
        if found is None:
            return f"the line {line!r} has no number"
        numbers.append(int(found.group()))
    for i in range(1, len(numbers)):
        if numbers[i] != numbers[i - 1] + 1:
            return f"after number {numbers[i - 1]} came {texts[i]!r}: each line counts one more"
    return ""
