"""`ros2 topic ...`: list, info, echo, hz, bw, pub.

``TopicMonitor`` is the one subscription behind echo, hz and bw, and behind
the Topics panel: it subscribes raw (serialized bytes), so sizes are known for
bandwidth and messages are deserialized only when someone looks at them.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from rclpy.node import Node
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSProfile,
    ReliabilityPolicy,
)
from rclpy.serialization import deserialize_message

from app.ros2cli.common import ACTION_MARKER, Ros2Error, VerbContext, wait_for_graph
from app.ros2cli.convert import (
    ConversionError,
    dump_yaml,
    field_value,
    from_yaml,
    import_type,
    message_repr,
    to_plain,
    to_yaml,
)

# ------------------------------------------------------------------ graph


def topic_types(node: Node, include_hidden: bool = False) -> dict[str, list[str]]:
    return {
        name: list(types)
        for name, types in node.get_topic_names_and_types()
        if include_hidden or ACTION_MARKER not in name
    }


def resolve_type(ctx: VerbContext, topic: str, given: str | None) -> type:
    """The message class for ``topic``: the given type, else the one on the graph."""
    if given:
        return import_type(given, "msg")
    wait_for_graph(ctx, lambda: topic in topic_types(ctx.node, include_hidden=True))
    types = topic_types(ctx.node, include_hidden=True).get(topic)
    if not types:
        raise Ros2Error(
            f"topic '{topic}' is not on the graph (see `ros2 topic list`); "
            "to wait for it anyway, give its type after the topic name"
        )
    if len(types) > 1:
        raise Ros2Error(f"topic '{topic}' has several types ({', '.join(types)}); give one")
    return import_type(types[0], "msg")


def matching_qos(node: Node, topic: str, depth: int = 10) -> QoSProfile:
    """A subscription QoS every current publisher is compatible with (as ros2 echo picks it)."""
    publishers = node.get_publishers_info_by_topic(topic)
    reliable = bool(publishers) and all(
        p.qos_profile.reliability == ReliabilityPolicy.RELIABLE for p in publishers
    )
    transient = bool(publishers) and all(
        p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in publishers
    )
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=depth,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if transient else DurabilityPolicy.VOLATILE,
    )


MEASURE_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=100,
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
)

# ---------------------------------------------------------------- monitor


@dataclass(frozen=True)
class RateStats:
    rate: float
    min_period: float
    max_period: float
    std_dev: float
    window: int

    def ros2_text(self) -> str:
        return (
            f"average rate: {self.rate:.3f}\n"
            f"\tmin: {self.min_period:.3f}s max: {self.max_period:.3f}s "
            f"std dev: {self.std_dev:.5f}s window: {self.window}"
        )


@dataclass(frozen=True)
class BandwidthStats:
    bytes_per_sec: float
    count: int
    mean: float
    min_size: int
    max_size: int

    def ros2_text(self) -> str:
        return (
            f"{_human(self.bytes_per_sec)}/s from {self.count} messages\n"
            f"\tMessage size mean: {_human(self.mean)} min: {_human(self.min_size)} "
            f"max: {_human(self.max_size)}"
        )


def _human(size: float) -> str:
    for unit in ("B", "KB", "MB"):
        if size < 1000 or unit == "MB":
            return f"{size:.2f} {unit}"
        size /= 1000
    return f"{size:.2f} MB"


class TopicMonitor:
    """One raw subscription: arrival stamps, sizes, and the last few messages.

    The subscription callback (executor thread) is the single writer; readers
    on other threads take the lock.
    """

    def __init__(
        self,
        node: Node,
        topic: str,
        msg_type: type,
        *,
        window: int = 10_000,
        keep: int = 100,
        qos: QoSProfile | int | None = None,
    ) -> None:
        # qos: a profile, a depth (reliable, volatile), or None to match the
        # topic's current publishers as `ros2 topic echo` does.
        self.topic = topic
        self.msg_type = msg_type
        self._node = node
        self._cond = threading.Condition()
        self._stamps: deque[float] = deque(maxlen=window)
        self._sizes: deque[tuple[float, int]] = deque(maxlen=window)
        self._recent: deque[tuple[float, bytes]] = deque(maxlen=keep)
        self.count = 0
        self._sub = node.create_subscription(
            msg_type,
            topic,
            self._on_message,
            matching_qos(node, topic) if qos is None else qos,
            raw=True,
        )

    def _on_message(self, data: bytes) -> None:
        now = time.monotonic()
        with self._cond:
            self._stamps.append(now)
            self._sizes.append((now, len(data)))
            self._recent.append((time.time(), data))
            self.count += 1
            self._cond.notify_all()

    def wait_for_count(self, count: int, timeout: float) -> bool:
        """Block (not the executor thread) until ``count`` messages arrived in total."""
        with self._cond:
            return self._cond.wait_for(lambda: self.count >= count, timeout)

    def message(self, index_from_end: int = 1) -> tuple[float, Any] | None:
        with self._cond:
            if len(self._recent) < index_from_end:
                return None
            stamp, data = self._recent[-index_from_end]
        return stamp, deserialize_message(data, self.msg_type)

    def recent(self, last: int | None = None) -> list[tuple[float, Any]]:
        """The newest ``last`` kept messages (all kept ones for None), oldest first."""
        with self._cond:
            raw = list(self._recent)
        if last is not None:
            raw = raw[-last:] if last > 0 else []
        return [(stamp, deserialize_message(data, self.msg_type)) for stamp, data in raw]

    def newest(self) -> Iterator[tuple[float, Any]]:
        """Kept messages newest first, each deserialised only when reached."""
        with self._cond:
            raw = list(self._recent)
        for stamp, data in reversed(raw):
            yield stamp, deserialize_message(data, self.msg_type)

    def rate_hz(self, window_sec: float = 5.0) -> float | None:
        """Mean rate over the last ``window_sec``; None with fewer than two messages."""
        stats = self.rate(window_sec)
        return stats.rate if stats else None

    def messages_since(self, count_before: int) -> list[tuple[float, Any]]:
        """Messages that arrived after the total count was ``count_before`` (as kept)."""
        with self._cond:
            fresh = min(self.count - count_before, len(self._recent))
            raw = list(self._recent)[len(self._recent) - fresh :] if fresh > 0 else []
        return [(stamp, deserialize_message(data, self.msg_type)) for stamp, data in raw]

    def rate(self, window_sec: float | None = None) -> RateStats | None:
        with self._cond:
            stamps = list(self._stamps)
        if window_sec is not None:
            now = time.monotonic()
            stamps = [s for s in stamps if now - s <= window_sec]
        if len(stamps) < 2:
            return None
        periods = [b - a for a, b in zip(stamps, stamps[1:], strict=False)]
        mean = (stamps[-1] - stamps[0]) / len(periods)
        if mean <= 0:
            return None
        std = math.sqrt(sum((p - mean) ** 2 for p in periods) / len(periods))
        return RateStats(1.0 / mean, min(periods), max(periods), std, len(stamps))

    def bandwidth(self, window_sec: float | None = None) -> BandwidthStats | None:
        with self._cond:
            sizes = list(self._sizes)
        if window_sec is not None:
            now = time.monotonic()
            sizes = [(t, s) for t, s in sizes if now - t <= window_sec]
        if len(sizes) < 2:
            return None
        span = sizes[-1][0] - sizes[0][0]
        values = [s for _t, s in sizes]
        if span <= 0:
            return None
        return BandwidthStats(
            sum(values[1:]) / span, len(values), sum(values) / len(values), min(values), max(values)
        )

    def close(self) -> None:
        self._node.destroy_subscription(self._sub)


# ------------------------------------------------------------------ verbs


def list_topics(ctx: VerbContext, show_types: bool = False, counts: bool = False) -> int:
    for name, types in sorted(topic_types(ctx.node).items()):
        line = name
        if show_types:
            line += f" [{', '.join(types)}]"
        if counts:
            pubs, subs = ctx.node.count_publishers(name), ctx.node.count_subscribers(name)
            line += f" ({pubs} publisher{'s' * (pubs != 1)}, {subs} subscriber{'s' * (subs != 1)})"
        ctx.write(line)
    return 0


def _qos_lines(qos: QoSProfile) -> list[str]:
    def policy(value: Any) -> str:
        return getattr(value, "name", str(value)).upper()

    def duration(value: Any) -> str:
        nanos = getattr(value, "nanoseconds", 0)
        return (
            "Infinite"
            if nanos in (0, 0x7FFFFFFFFFFFFFFF) or nanos >= 2**63 - 1
            else (f"{nanos} nanoseconds")
        )

    depth = "UNKNOWN" if qos.history != HistoryPolicy.KEEP_LAST else str(qos.depth)
    return [
        "QoS profile:",
        f"  Reliability: {policy(qos.reliability)}",
        f"  History (Depth): {policy(qos.history)} ({depth})",
        f"  Durability: {policy(qos.durability)}",
        f"  Lifespan: {duration(qos.lifespan)}",
        f"  Deadline: {duration(qos.deadline)}",
        f"  Liveliness: {policy(qos.liveliness)}",
        f"  Liveliness lease duration: {duration(qos.liveliness_lease_duration)}",
    ]


def topic_info(ctx: VerbContext, topic: str, verbose: bool = False) -> int:
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
            for line in _qos_lines(info.qos_profile):
                ctx.write(line)
    return 0


def _deadline(ctx: VerbContext) -> float:
    limit = ctx.limits.max_seconds
    return time.monotonic() + limit if limit else math.inf


def echo(
    ctx: VerbContext,
    topic: str,
    type_text: str | None = None,
    *,
    once: bool = False,
    field: str | None = None,
    count: int | None = None,
) -> int:
    msg_type = resolve_type(ctx, topic, type_text)
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


def _measure(ctx: VerbContext, topic: str, type_text: str | None, window: int, report) -> int:
    msg_type = resolve_type(ctx, topic, type_text)
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


def hz(ctx: VerbContext, topic: str, type_text: str | None = None, window: int = 10_000) -> int:
    def report(monitor: TopicMonitor) -> str | None:
        stats = monitor.rate()
        return stats.ros2_text() if stats else None

    return _measure(ctx, topic, type_text, window, report)


def bw(ctx: VerbContext, topic: str, type_text: str | None = None, window: int = 100) -> int:
    def report(monitor: TopicMonitor) -> str | None:
        stats = monitor.bandwidth()
        return stats.ros2_text() if stats else None

    return _measure(ctx, topic, type_text, window, report)


def pub(
    ctx: VerbContext,
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
    msg = from_yaml(msg_type, values)
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


__all__ = ["ConversionError", "TopicMonitor", "RateStats", "BandwidthStats"]
