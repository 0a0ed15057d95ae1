"""`ros2 topic ...`: list, info, type, find, echo, hz, bw, pub (monitoring: app.ros.monitor)."""

from __future__ import annotations

import math
import time
from typing import Any

from app.ros.context import CallContext
from app.ros.convert import (
    dump_yaml,
    field_value,
    fields_of,
    fill,
    import_type,
    message_repr,
    parse_yaml,
    to_plain,
    to_yaml,
)
from app.ros.errors import Ros2Error
from app.ros.graph import resolve_topic_type, topic_types
from app.ros.monitor import TopicMonitor
from app.ros.qos import MEASURE_QOS, qos_lines

# ------------------------------------------------------------------ verbs


def list_topics(ctx: CallContext, show_types: bool = False, counts: bool = False) -> int:
    for name, types in sorted(topic_types(ctx.node).items()):
        line = name
        if show_types:
            line += f" [{', '.join(types)}]"
        if counts:
            pubs, subs = ctx.node.count_publishers(name), ctx.node.count_subscribers(name)
            line += f" ({pubs} publisher{'s' * (pubs != 1)}, {subs} subscriber{'s' * (subs != 1)})"
        ctx.write(line)
    return 0


def topic_info(ctx: CallContext, topic: str, verbose: bool = False) -> int:
    types = topic_types(ctx.node, include_hidden=True).get(topic)
    if not types:
        raise Ros2Error(f"unknown topic '{topic}' (see `ros2 topic list`)")
    ctx.write(f"Type: {', '.join(types)}")
    for label, infos in (
        ("Publisher", ctx.node.get_publishers_info_by_topic(topic)),
        ("Subscription", ctx.node.get_subscriptions_info_by_topic(topic)),
    ):
        if verbose:
            ctx.write("")
        ctx.write(f"{label} count: {len(infos)}")
        if not verbose:
            continue
        for info in infos:
            ctx.write("")
            ctx.write(f"Node name: {info.node_name}")
            ctx.write(f"Node namespace: {info.node_namespace}")
            ctx.write(f"Topic type: {info.topic_type}")
            ctx.write(f"Endpoint type: {getattr(info.endpoint_type, 'name', info.endpoint_type)}")
            gid = ".".join(f"{b:02x}" for b in info.endpoint_gid)
            ctx.write(f"GID: {gid}")
            for line in qos_lines(info.qos_profile):
                ctx.write(line)
    return 0


def topic_type(ctx: CallContext, topic: str) -> int:
    types = topic_types(ctx.node, include_hidden=True).get(topic)
    if not types:
        raise Ros2Error(f"unknown topic '{topic}' (see `ros2 topic list`)")
    for type_text in types:
        ctx.write(type_text)
    return 0


def find(ctx: CallContext, type_text: str) -> int:
    """The topics that carry a type (the full name, as `ros2 topic list -t` prints it)."""
    for name, types in sorted(topic_types(ctx.node).items()):
        if type_text in types:
            ctx.write(name)
    return 0


def _deadline(ctx: CallContext) -> float:
    limit = ctx.limits.max_seconds
    return time.monotonic() + limit if limit else math.inf


def echo(
    ctx: CallContext,
    topic: str,
    type_text: str | None = None,
    *,
    once: bool = False,
    field: str | None = None,
    count: int | None = None,
) -> int:
    msg_type = resolve_topic_type(ctx, topic, type_text)
    limit = 1 if once else count or ctx.limits.max_messages
    monitor = TopicMonitor(ctx.node, topic, msg_type, keep=200, window=16)
    shown = 0
    deadline = _deadline(ctx)
    try:
        while limit is None or shown < limit:
            ctx.check_cancel()
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                break
            seen = monitor.count
            if seen <= shown:
                monitor.wait_for_count(shown + 1, min(0.1, remaining))
                continue
            for _stamp, msg in monitor.messages_since(shown):
                if limit is not None and shown >= limit:
                    break
                shown += 1
                if field:
                    value = to_plain(field_value(msg, field))
                    ctx.write(_field_text(value))
                else:
                    ctx.write(to_yaml(msg))
                ctx.write("---")
            shown = max(shown, seen)  # messages dropped from the buffer count as shown
    finally:
        monitor.close()
    if shown == 0:
        ctx.write(f"(no message on {topic} within {ctx.limits.max_seconds:g} s)")
    return 0


def _field_text(value: Any) -> str:
    if isinstance(value, dict | list):
        return dump_yaml(value)
    return str(value)


def _measure(ctx: CallContext, topic: str, type_text: str | None, window: int, report) -> int:
    msg_type = resolve_topic_type(ctx, topic, type_text)
    # Best effort, as ros2 hz/bw subscribe: measuring must not slow a reliable publisher.
    monitor = TopicMonitor(ctx.node, topic, msg_type, window=window, keep=1, qos=MEASURE_QOS)
    deadline = _deadline(ctx)
    reported = False
    try:
        while time.monotonic() < deadline:
            ctx.sleep(min(1.0, max(0.0, deadline - time.monotonic())))
            text = report(monitor)
            if text:
                ctx.write(text)
                reported = True
    finally:
        monitor.close()
    if not reported:
        ctx.write(f"(no messages on {topic}, or too few to measure)")
    return 0


def hz(ctx: CallContext, topic: str, type_text: str | None = None, window: int = 10_000) -> int:
    def report(monitor: TopicMonitor) -> str | None:
        # ros2's own two lines (the tutorials show them), then what ros2 cannot
        # tell: the publisher's rate by its clock and the samples missed here.
        stats = monitor.rate()
        if stats is None:
            return None
        published = monitor.published_rate()
        extra = f"\n{published.ros2_line(monitor.why_missed())}" if published else ""
        return stats.ros2_text() + extra

    return _measure(ctx, topic, type_text, window, report)


def bw(ctx: CallContext, topic: str, type_text: str | None = None, window: int = 100) -> int:
    def report(monitor: TopicMonitor) -> str | None:
        stats = monitor.bandwidth()
        return stats.ros2_text() if stats else None

    return _measure(ctx, topic, type_text, window, report)


def with_stamps(cls: type, data: dict[str, Any], stamp: dict[str, int]) -> dict[str, Any]:
    """`ros2 topic pub`'s keywords: a Header given as "auto", a Time given as "now"."""
    filled = dict(data)
    for name, ros_type, _slot in fields_of(cls):
        value = filled.get(name)
        if value == "auto" and ros_type == "std_msgs/Header":
            filled[name] = {"stamp": stamp, "frame_id": ""}
        elif value == "now" and ros_type == "builtin_interfaces/Time":
            filled[name] = stamp
        elif isinstance(value, dict) and ros_type.count("/") == 1:  # a nested message
            filled[name] = with_stamps(import_type(ros_type), value, stamp)
    return filled


def _stamped(ctx: CallContext, msg_type: type, data: dict[str, Any]) -> Any:
    now = ctx.node.get_clock().now().to_msg()
    return fill(msg_type, with_stamps(msg_type, data, {"sec": now.sec, "nanosec": now.nanosec}))


def pub(
    ctx: CallContext,
    topic: str,
    type_text: str,
    values: str = "",
    *,
    once: bool = False,
    rate: float = 1.0,
    times: int | None = None,
    wait_matching: int | None = None,
) -> int:
    msg_type = import_type(type_text, "msg")
    data = parse_yaml(values)
    stamps = with_stamps(msg_type, data, {"sec": 0, "nanosec": 0}) != data
    msg = _stamped(ctx, msg_type, data)
    if not rate > 0 or not math.isfinite(rate):
        raise Ros2Error(f"rate must be a positive number of Hz, got {rate}")
    if once:
        times = 1
    if wait_matching is None:
        wait_matching = 1 if times else 0
    existing = topic_types(ctx.node, include_hidden=True).get(topic)
    if existing and type_text and import_type(existing[0]) is not msg_type:
        raise Ros2Error(f"topic '{topic}' already carries {existing[0]}, not {type_text}")
    publisher = ctx.node.create_publisher(msg_type, topic, 10)
    try:
        wait_end = time.monotonic() + ctx.limits.service_timeout
        if wait_matching:
            ctx.write(f"Waiting for at least {wait_matching} matching subscription(s)...")
        while publisher.get_subscription_count() < wait_matching:
            if time.monotonic() > wait_end:
                ctx.write("(no subscriber matched; publishing anyway)")
                break
            ctx.sleep(0.05)
        ctx.write("publisher: beginning loop")
        deadline = _deadline(ctx)
        start = time.monotonic()
        sent = 0
        while times is None or sent < times:
            if stamps:  # "auto"/"now": the time of each message, as ros2 topic pub does
                msg = _stamped(ctx, msg_type, data)
            publisher.publish(msg)
            sent += 1
            ctx.write(f"publishing #{sent}: {message_repr(msg)}")
            ctx.write("")
            if times is not None and sent >= times:
                break
            next_time = start + sent / rate
            if next_time > deadline:
                break
            ctx.sleep(max(0.0, next_time - time.monotonic()))
        if times == 1:
            ctx.sleep(0.5)  # let a reliable subscriber receive it before we vanish
    finally:
        ctx.node.destroy_publisher(publisher)
    return 0
