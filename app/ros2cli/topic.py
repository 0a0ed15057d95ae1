"""`ros2 topic ...`: list, info, type, find, echo, hz, bw, pub (monitoring: app.ros.monitor)."""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TypeVar

import yaml
from rclpy.duration import Duration
from rclpy.exceptions import InvalidTopicNameException
from rclpy.expand_topic_name import expand_topic_name
from rclpy.publisher import Publisher
from rclpy.qos import (
    DurabilityPolicy,
    QoSDurabilityPolicy,
    QoSHistoryPolicy,
    QoSLivelinessPolicy,
    QoSPresetProfiles,
    QoSProfile,
    QoSReliabilityPolicy,
    ReliabilityPolicy,
)
from rclpy.topic_endpoint_info import TopicEndpointInfo
from rclpy.validate_full_topic_name import validate_full_topic_name

from app.ros.context import CallContext
from app.ros.convert import (
    RosType,
    fields_of,
    fill,
    import_type,
    is_message,
    message_repr,
    parse_yaml,
)
from app.ros.errors import Ros2Error
from app.ros.graph import topic_types
from app.ros.monitor import TopicMonitor
from app.ros.qos import MEASURE_QOS, suit_publishers
from app.ros2cli.common import (
    Commands,
    Ros2cliMessage,
    SilentFailure,
    Verb,
    ros2_type,
    visible,
    write_names,
    write_text,
)
from app.ros2cli.msg_yaml import ECHO_TRUNCATE_LENGTH, message_to_csv, message_to_yaml
from app.ros2cli.options import (
    nonnegative_int,
    not_here,
    positive_float,
    positive_int,
    spin_time,
    strategy,
    unsigned_int,
)

M = TypeVar("M")  # a message (its generated class is untyped)

# ------------------------------------------------------------------ verbs


def _topics(ctx: CallContext, include_hidden: bool) -> list[tuple[str, list[str]]]:
    return sorted(visible(ctx.node.get_topic_names_and_types(), include_hidden))


def _counted(topics: list[tuple[str, list[str], int]], noun: str) -> list[str]:
    """`ros2 topic list -v`'s section: one ' * name [types] N nouns' line per used topic."""
    lines = [f"{noun.capitalize()} topics:"]
    for name, types, n in topics:
        if n:
            kind = "publisher" if noun == "published" else "subscriber"
            lines.append(f" * {name} [{', '.join(types)}] {n} {kind}{'s' * (n > 1)}")
    return lines + [""]


def list_topics(
    ctx: CallContext,
    show_types: bool = False,
    verbose: bool = False,
    count: bool = False,
    include_hidden: bool = False,
) -> int:
    topics = _topics(ctx, include_hidden)
    if count:
        ctx.write(str(len(topics)))
        return 0
    if verbose and topics:
        node = ctx.node
        for noun, counter in (
            ("published", node.count_publishers),
            ("subscribed", node.count_subscribers),
        ):
            for line in _counted([(n, t, counter(n)) for n, t in topics], noun):
                ctx.write(line)
        return 0
    for name, types in topics:
        ctx.write(f"{name} [{', '.join(types)}]" if show_types else name)
    return 0


def topic_info(ctx: CallContext, topic: str, verbose: bool = False) -> int:
    """As ros2cli: -v adds an empty line after each line and rclpy's text of each endpoint."""
    types = dict(_topics(ctx, include_hidden=True)).get(topic)
    if not types:
        raise Ros2cliMessage(f"Unknown topic '{topic}'")
    end = [""] if verbose else []
    for line in [f"Type: {types[0] if len(types) == 1 else types}", *end]:
        ctx.write(line)
    for label, counter, infos in (
        ("Publisher", ctx.node.count_publishers, ctx.node.get_publishers_info_by_topic),
        ("Subscription", ctx.node.count_subscribers, ctx.node.get_subscriptions_info_by_topic),
    ):
        for line in [f"{label} count: {counter(topic)}", *end]:
            ctx.write(line)
        if verbose:
            for info in infos(topic):
                # rclpy's TopicEndpointInfo text: names, type, type hash, GID, QoS profile.
                write_text(ctx, f"{info}\n")
    return 0


def topic_type(ctx: CallContext, topic: str, include_hidden: bool = False) -> int:
    types = dict(_topics(ctx, include_hidden)).get(topic)
    if not types:
        raise SilentFailure(f"no topic '{topic}' on the graph")
    for type_text in types:
        ctx.write(type_text)
    return 0


def find(
    ctx: CallContext, type_text: str, count: bool = False, include_hidden: bool = False
) -> int:
    """The topics that carry a type (the full name, as `ros2 topic list -t` prints it)."""
    found = [name for name, types in _topics(ctx, include_hidden) if type_text in types]
    return write_names(ctx, found, count)


def _deadline(ctx: CallContext) -> float:
    limit = ctx.limits.max_seconds
    return time.monotonic() + limit if limit else math.inf


def qos_fallback_lines(publishers: list[TopicEndpointInfo]) -> list[str]:
    """What `ros2 topic echo` says when only some publishers are reliable or transient local."""
    lines = []
    for attr, good, name, fallback in (
        ("reliability", ReliabilityPolicy.RELIABLE, "RELIABLE", "BEST_EFFORT"),
        ("durability", DurabilityPolicy.TRANSIENT_LOCAL, "TRANSIENT_LOCAL", "VOLATILE"),
    ):
        offering = sum(getattr(p.qos_profile, attr) == good for p in publishers)
        if 0 < offering < len(publishers):
            policy = "QoSReliabilityPolicy" if attr == "reliability" else "QoSDurabilityPolicy"
            lines.append(
                f"Some, but not all, publishers are offering {policy}.{name}. Falling back to "
                f"{policy}.{fallback} as it will connect to all publishers"
            )
    return lines


@dataclass(frozen=True)
class QosOptions:
    """`topic echo`/`pub`'s --qos-* options: a preset by its short key, and overrides."""

    profile: str
    reliability: str | None = None
    durability: str | None = None
    depth: int | None = None
    history: str | None = None
    liveliness: str | None = None
    lease_seconds: float | None = None

    def overridden(self) -> bool:
        overrides = (self.reliability, self.durability, self.depth, self.history)
        return any(v is not None for v in (*overrides, self.liveliness, self.lease_seconds))

    def profile_with_overrides(self) -> QoSProfile:
        """The preset with each given policy in its place, as ros2cli builds it."""
        qos = QoSPresetProfiles.get_from_short_key(self.profile)
        if self.history:
            qos.history = QoSHistoryPolicy.get_from_short_key(self.history)
        if self.durability:
            qos.durability = QoSDurabilityPolicy.get_from_short_key(self.durability)
        if self.reliability:
            qos.reliability = QoSReliabilityPolicy.get_from_short_key(self.reliability)
        if self.liveliness:
            qos.liveliness = QoSLivelinessPolicy.get_from_short_key(self.liveliness)
        if self.lease_seconds and self.lease_seconds >= 0:
            qos.liveliness_lease_duration = Duration(seconds=self.lease_seconds)
        if self.depth and self.depth >= 0:
            qos.depth = self.depth
        elif qos.durability == DurabilityPolicy.TRANSIENT_LOCAL and qos.depth == 0:
            qos.depth = 1
        return qos


ECHO_QOS = QosOptions("sensor_data")
PUB_QOS = QosOptions("default")


def _echo_qos(ctx: CallContext, topic: str, options: QosOptions) -> QoSProfile | None:
    """The subscription's QoS, as ros2cli's echo chooses it (None: our matching default).

    With an override, exactly the asked profile; else the preset, made reliable or
    transient local only when every publisher offers it (and saying so when some do).
    """
    if options.overridden():
        return options.profile_with_overrides()
    publishers = ctx.node.get_publishers_info_by_topic(topic)
    for line in qos_fallback_lines(publishers):
        ctx.write(line)
    if options.profile == ECHO_QOS.profile:
        return None  # the same choice, made by app.ros.qos.matching_qos
    qos = QoSPresetProfiles.get_from_short_key(options.profile)
    return suit_publishers(qos, publishers) if publishers else qos


def _full_topic_name(ctx: CallContext, topic: str) -> str:
    """The name as ros2cli looks it up: relative to the CLI's node, and valid, or its words."""
    try:
        expanded = expand_topic_name(topic, ctx.node.get_name(), ctx.node.get_namespace())
        validate_full_topic_name(expanded)
    except (ValueError, InvalidTopicNameException) as exc:
        raise Ros2cliMessage(str(exc)) from None
    return expanded


def _known_type(ctx: CallContext, topic: str) -> str | None:
    types = topic_types(ctx.node, include_hidden=True).get(topic)
    if types and len(types) > 1:
        raise Ros2cliMessage(
            f"Cannot echo topic '{topic}', as it contains more than one type: [{', '.join(types)}]"
        )
    return types[0] if types else None


def not_published_yet(topic: str) -> str:
    return f"WARNING: topic [{topic}] does not appear to be published yet"


def _echo_type(ctx: CallContext, topic: str, type_text: str | None) -> RosType:
    if type_text:
        return ros2_type(type_text, "msg")
    full = _full_topic_name(ctx, topic)
    found = _known_type(ctx, full)  # no wait: the CLI has let its node discover the graph
    if found is None:
        ctx.write(not_published_yet(topic))
        raise Ros2cliMessage("Could not determine the type for the passed topic")
    return import_type(found, "msg")


def _measured_type(ctx: CallContext, topic: str) -> type | None:
    """`topic hz`/`bw` of a topic not on the graph yet: say so once, then wait for it.

    None when the wait ends first (the Console's bound, or Ctrl+C: ros2 then ends
    quietly with exit code 0, its wait loop simply stops).
    """
    full = _full_topic_name(ctx, topic)
    found = _known_type(ctx, full)
    if found is None:
        ctx.write(not_published_yet(topic))
        deadline = _deadline(ctx)
        while (found := _known_type(ctx, full)) is None:
            if time.monotonic() > deadline or ctx.cancel.wait(0.1):
                return None
    return import_type(found, "msg")


def _selected(msg: object, field: list[str] | None, field_text: str) -> object:
    for part in field or []:
        try:
            msg = getattr(msg, part)
        except AttributeError as exc:
            raise Ros2cliMessage(f"Invalid field '{field_text}': {exc}") from None
    return msg


@dataclass(frozen=True)
class EchoStyle:
    """How `ros2 topic echo` prints: its --truncate-length, --no-arr, --no-str, ... options."""

    truncate_length: int | None = ECHO_TRUNCATE_LENGTH
    no_arr: bool = False
    no_str: bool = False
    flow_style: bool = False
    csv: bool = False


def echo_text(value: object, style: EchoStyle = EchoStyle()) -> str:
    """One echoed message as ros2cli prints it, up to and with its closing '---'."""
    if not is_message(value):
        return f"{value}\n---"  # a selected field that is not a message: printed as Python does
    options = {"no_arr": style.no_arr, "no_str": style.no_str}
    if style.csv:
        return message_to_csv(value, style.truncate_length, **options)
    return (
        message_to_yaml(value, style.truncate_length, flow_style=style.flow_style, **options)
        + "---"
    )


def echo(
    ctx: CallContext,
    topic: str,
    type_text: str | None = None,
    *,
    once: bool = False,
    field: str | None = None,
    count: int | None = None,
    style: EchoStyle = EchoStyle(),
    timeout: float | None = None,
    qos: QosOptions = ECHO_QOS,
) -> int:
    parts = None
    if field is not None:
        parts = [p for p in field.split(".") if p]
        if not parts:
            raise Ros2cliMessage(f"Invalid field value '{field}'")
    msg_type = _echo_type(ctx, topic, type_text)
    profile = _echo_qos(ctx, topic, qos)
    limit = 1 if once else count or ctx.limits.max_messages
    monitor = TopicMonitor(ctx.node, topic, msg_type, keep=200, window=16, qos=profile)
    shown = 0
    deadline = _deadline(ctx)
    if timeout is not None:
        deadline = min(deadline, time.monotonic() + timeout)
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
                write_text(ctx, echo_text(_selected(msg, parts, field or ""), style))
            shown = max(shown, seen)  # messages dropped from the buffer count as shown
    finally:
        monitor.close()
    if shown == 0 and timeout is None and ctx.limits.max_seconds:
        # The Console's own bound (ros2 would keep waiting): say why nothing came.
        ctx.write(f"(no message on {topic} within {ctx.limits.max_seconds:g} s)")
    return 0


def _measure(
    ctx: CallContext, topic: str, type_text: str | None, window: int, report, first: str = ""
) -> int:
    msg_type = ros2_type(type_text, "msg") if type_text else _measured_type(ctx, topic)
    if msg_type is None:
        if not ctx.cancel.is_set():
            ctx.write(f"(no messages on {topic}, or too few to measure)")
        return 0
    # Best effort, as ros2 hz/bw subscribe: measuring must not slow a reliable publisher.
    monitor = TopicMonitor(ctx.node, topic, msg_type, window=window, keep=1, qos=MEASURE_QOS)
    if first:
        ctx.write(first)
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


def bandwidth_text(per_sec: float, count: int, mean: float, low: float, high: float) -> str:
    """`ros2 topic bw`'s two lines: one unit for all four sizes, chosen by the rate."""
    if per_sec < 1000:
        unit, scale, digits = "B", 1.0, 0
    elif per_sec < 1_000_000:
        unit, scale, digits = "KB", 1000.0, 2
    else:
        unit, scale, digits = "MB", 1_000_000.0, 2
    rate, mean_t, low_t, high_t = (
        f"{value / scale:.{digits}f} {unit}" for value in (per_sec, mean, low, high)
    )
    return (
        f"{rate}/s from {count} messages\n\tMessage size mean: {mean_t} min: {low_t} max: {high_t}"
    )


def bw(ctx: CallContext, topic: str, type_text: str | None = None, window: int = 100) -> int:
    def report(monitor: TopicMonitor) -> str | None:
        s = monitor.bandwidth()
        if s is None:
            return None
        return bandwidth_text(s.bytes_per_sec, s.count, s.mean, s.min_size, s.max_size)

    return _measure(ctx, topic, type_text, window, report, f"Subscribed to [{topic}]")


def with_stamps(
    cls: RosType, data: Mapping[str, object], stamp: dict[str, int]
) -> dict[str, object]:
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


def _stamped(ctx: CallContext, msg_type: type[M], data: Mapping[str, object]) -> M:
    now = ctx.node.get_clock().now().to_msg()
    return fill(msg_type, with_stamps(msg_type, data, {"sec": now.sec, "nanosec": now.nanosec}))


def _wait_for_subscribers(
    ctx: CallContext, publisher: Publisher, wanted: int, max_wait_time: float | None
) -> None:
    """ros2cli's wait: a 'Waiting for ...' line each second while too few subscriptions match."""
    started = time.monotonic()
    # The Console bounds the wait (ros2 waits endlessly unless --max-wait-time-secs).
    console_limit = ctx.limits.max_seconds if max_wait_time is None else None
    checks = 0
    while publisher.get_subscription_count() < wanted:
        if checks % 10 == 0:
            ctx.write(f"Waiting for at least {wanted} matching subscription(s)...")
        waited = time.monotonic() - started
        if max_wait_time is not None and waited >= max_wait_time:
            raise Ros2cliMessage(
                f"Timed out waiting for subscribers: Expected {wanted} subcribers but only "
                f"got {publisher.get_subscription_count()} subscribers"
            )
        if console_limit and waited >= console_limit:
            ctx.write("(no subscriber matched; publishing anyway)")
            return
        checks += 1
        ctx.sleep(0.1)


def pub(
    ctx: CallContext,
    topic: str,
    type_text: str,
    values: str = "{}",
    *,
    once: bool = False,
    rate: float = 1.0,
    times: int | None = None,
    wait_matching: int | None = None,
    print_nth: int = 1,
    max_wait_time: float | None = None,
    keep_alive: float = 0.1,
    qos: QosOptions = PUB_QOS,
) -> int:
    """`ros2 topic pub`: wait for subscribers if asked, then publish and print as ros2cli."""
    if not rate > 0 or not math.isfinite(rate):
        raise Ros2Error(f"rate must be a positive number of Hz, got {rate}")
    msg_type = ros2_type(type_text, "msg")
    try:
        loaded = yaml.safe_load(values or "{}")
    except yaml.YAMLError:
        loaded = None  # parse_yaml below names the YAML mistake
    if loaded is not None and not isinstance(loaded, dict):
        raise Ros2cliMessage("The passed value needs to be a dictionary in YAML format")
    data = parse_yaml(values)
    stamps = with_stamps(msg_type, data, {"sec": 0, "nanosec": 0}) != data
    msg = _stamped(ctx, msg_type, data)
    times = 1 if once else (times or 0)
    if wait_matching is None:
        wait_matching = int(times != 0)
    if wait_matching == 0 and max_wait_time is not None:
        raise Ros2cliMessage(
            "--max-wait-time-secs option is only effective with "
            "--wait-matching-subscriptions, --once or --times"
        )
    existing = topic_types(ctx.node, include_hidden=True).get(topic)
    if existing and type_text and import_type(existing[0]) is not msg_type:
        raise Ros2Error(f"topic '{topic}' already carries {existing[0]}, not {type_text}")
    publisher = ctx.node.create_publisher(msg_type, topic, qos.profile_with_overrides())
    try:
        _wait_for_subscribers(ctx, publisher, wait_matching, max_wait_time)
        ctx.write("publisher: beginning loop")
        deadline = _deadline(ctx)
        start = time.monotonic()
        sent = 0
        while times == 0 or sent < times:
            if stamps:  # "auto"/"now": the time of each message, as ros2 topic pub does
                msg = _stamped(ctx, msg_type, data)
            sent += 1
            if print_nth and sent % print_nth == 0:
                ctx.write(f"publishing #{sent}: {message_repr(msg)}")
                ctx.write("")
            publisher.publish(msg)
            if times and sent >= times:
                break
            next_time = start + sent / rate
            if next_time > deadline:
                break
            ctx.sleep(max(0.0, next_time - time.monotonic()))
        # Let the last message reach a reliable subscriber before the publisher goes.
        ctx.sleep(max(keep_alive, 0.5 if times == 1 else 0.0))
    finally:
        ctx.node.destroy_publisher(publisher)
    return 0


# --- arguments: `ros2 topic ...` as ros2cli takes them


def qos_options(p: argparse.ArgumentParser, verb: str, default_profile: str) -> None:
    """`topic echo` and `topic pub`'s QoS options (read back by ``qos_of``)."""
    history = QoSPresetProfiles.get_from_short_key(default_profile).history.short_key
    compatible = "default: Compatible profile with running endpoints )"
    p.add_argument(
        "--qos-profile",
        choices=QoSPresetProfiles.short_keys(),
        default=default_profile,
        help=f"Quality of service preset profile to {verb} with (default: {default_profile})",
    )
    p.add_argument(
        "--qos-depth",
        metavar="N",
        type=int,
        help=f"Queue size setting to {verb} with (overrides depth value of --qos-profile option)",
    )
    p.add_argument(
        "--qos-history",
        choices=QoSHistoryPolicy.short_keys(),
        help=f"History of samples setting to {verb} with (overrides history value of "
        f"--qos-profile option, default: {history})",
    )
    p.add_argument(
        "--qos-reliability",
        choices=QoSReliabilityPolicy.short_keys(),
        help=f"Quality of service reliability setting to {verb} with (overrides "
        f"reliability value of --qos-profile option, {compatible}",
    )
    p.add_argument(
        "--qos-durability",
        choices=QoSDurabilityPolicy.short_keys(),
        help=f"Quality of service durability setting to {verb} with (overrides "
        f"durability value of --qos-profile option, {compatible}",
    )
    p.add_argument(
        "--qos-liveliness",
        choices=QoSLivelinessPolicy.short_keys(),
        help=f"Quality of service liveliness setting to {verb} with (overrides "
        "liveliness value of --qos-profile option",
    )
    p.add_argument(
        "--qos-liveliness-lease-duration-seconds",
        type=float,
        help=f"Quality of service liveliness lease duration setting to {verb} with "
        "(overrides liveliness lease duration value of --qos-profile option",
    )


def qos_of(a: argparse.Namespace) -> QosOptions:
    return QosOptions(
        a.qos_profile,
        reliability=a.qos_reliability,
        durability=a.qos_durability,
        depth=a.qos_depth,
        history=a.qos_history,
        liveliness=a.qos_liveliness,
        lease_seconds=a.qos_liveliness_lease_duration_seconds,
    )


HIDDEN_TOPICS_HELP = "Consider hidden topics as well"


def add_verbs(v: Commands, verb: Verb) -> None:
    p = verb(
        v,
        "list",
        "Output a list of available topics",
        lambda c, a: list_topics(
            c, a.show_types, a.verbose, a.count_topics, a.include_hidden_topics
        ),
    )
    strategy(p)
    p.add_argument(
        "-t", "--show-types", action="store_true", help="Additionally show the topic type"
    )
    p.add_argument(
        "-c",
        "--count-topics",
        action="store_true",
        help="Only display the number of topics discovered",
    )
    p.add_argument("--include-hidden-topics", action="store_true", help=HIDDEN_TOPICS_HELP)
    p.add_argument(
        "-v", "--verbose", action="store_true", help="List full details about each topic"
    )

    p = verb(
        v,
        "info",
        "Print information about a topic",
        lambda c, a: topic_info(c, a.topic_name, a.verbose),
    )
    strategy(p)
    p.add_argument("topic_name", help="Name of the ROS topic to get info (e.g. '/chatter')")
    p.add_argument(
        "--verbose",
        "-v",
        action="store_true",
        help="Prints detailed information like the node name, node namespace, topic type, "
        "topic type hash, GUID, and QoS Profile of the publishers and subscribers to this topic",
    )

    p = verb(
        v,
        "type",
        "Print a topic's type",
        lambda c, a: topic_type(c, a.topic_name, a.include_hidden_topics),
    )
    strategy(p)
    p.add_argument("topic_name", help="Name of the ROS topic to get type (e.g. '/chatter')")

    p = verb(
        v,
        "find",
        "Output a list of available topics of a given type",
        lambda c, a: find(c, a.topic_type, a.count_topics, a.include_hidden_topics),
    )
    strategy(p)
    # (sic: ros2cli's example says std_msg)
    p.add_argument(
        "topic_type", help="Name of the ROS topic type to filter for (e.g. 'std_msg/msg/String')"
    )
    p.add_argument(
        "-c",
        "--count-topics",
        action="store_true",
        help="Only display the number of topics discovered",
    )
    p.add_argument("--include-hidden-topics", action="store_true", help=HIDDEN_TOPICS_HELP)

    _add_echo(v, verb)

    p = verb(
        v,
        "hz",
        "Print the average publishing rate to screen",
        lambda c, a: hz(c, a.topic_name, None, a.window_size),
    )
    p.add_argument("topic_name", help="Name of the ROS topic to listen to (e.g. '/chatter')")
    p.add_argument(
        "--window",
        "-w",
        dest="window_size",
        type=positive_int,
        default=10_000,
        metavar="WINDOW",
        help="window size, in # of messages, for calculating rate (default: 10000)",
    )
    not_here(
        p, "--filter", metavar="EXPR", help="only measure messages matching the specified "
        "Python expression",
    )  # fmt: skip
    not_here(
        p,
        "--wall-time",
        flag=True,
        help="calculates rate using wall time which can be helpful when clock is not "
        "published during simulation",
    )
    spin_time(p)

    p = verb(
        v,
        "bw",
        "Display bandwidth used by topic",
        lambda c, a: bw(c, a.topic, None, a.window),
    )
    p.add_argument("topic", help="Topic name to monitor for bandwidth utilization")
    p.add_argument(
        "--window",
        "-w",
        type=positive_int,
        default=100,
        metavar="WINDOW",
        help="maximum window size, in # of messages, for calculating rate (default: 100)",
    )
    spin_time(p)

    _add_pub(v, verb)


def _add_echo(v: Commands, verb: Verb) -> None:
    p = verb(
        v,
        "echo",
        "Output messages from a topic",
        lambda c, a: echo(
            c,
            a.topic_name,
            a.message_type,
            once=a.once,
            field=a.field,
            style=EchoStyle(
                truncate_length=None if a.full_length else a.truncate_length,
                no_arr=a.no_arr,
                no_str=a.no_str,
                flow_style=a.flow_style,
                csv=a.csv,
            ),
            timeout=a.timeout,
            qos=qos_of(a),
        ),
    )
    strategy(p)
    p.add_argument("topic_name", help="Name of the ROS topic to listen to (e.g. '/chatter')")
    p.add_argument(
        "message_type", nargs="?", help="Type of the ROS message (e.g. 'std_msgs/msg/String')"
    )
    qos_options(p, "subscribe", "sensor_data")
    p.add_argument(
        "--csv",
        action="store_true",
        help="Output all recursive fields separated by commas (e.g. for plotting). If "
        "--include-message-info is also passed, the following fields are prepended: "
        "source_timestamp, received_timestamp, publication_sequence_number, "
        "reception_sequence_number.",
    )
    p.add_argument(
        "--field",
        type=str,
        default=None,
        help="Echo a selected field of a message. Use '.' to select sub-fields. For example, "
        "to echo the position field of a nav_msgs/msg/Odometry message: "
        "'ros2 topic echo /odom --field pose.pose.position'",
    )
    p.add_argument(
        "--full-length",
        "-f",
        action="store_true",
        help="Output all elements for arrays, bytes, and string with a length > "
        "'--truncate-length', by default they are truncated after '--truncate-length' "
        "elements with '...''",
    )
    p.add_argument(
        "--truncate-length",
        "-l",
        type=unsigned_int,
        default=128,
        help="The length to truncate arrays, bytes, and string to (default: 128)",
    )
    p.add_argument("--no-arr", action="store_true", help="Don't print array fields of messages")
    p.add_argument("--no-str", action="store_true", help="Don't print string fields of messages")
    # (sic: ros2cli's help says block style for the option that asks for the flow style)
    p.add_argument(
        "--flow-style",
        action="store_true",
        help="Print collections in the block style (not available with csv format)",
    )
    not_here(p, "--no-lost-messages", flag=True, help="Don't report when a message is lost")
    not_here(p, "--raw", flag=True, help="Echo the raw binary representation")
    not_here(
        p,
        "--filter",
        dest="filter_expr",
        help="Python expression to filter messages that are printed. Expression can use "
        "Python builtins as well as m (the message).",
    )
    p.add_argument(
        "--once", action="store_true", help="Print the first message received and then exit."
    )
    p.add_argument(
        "--timeout",
        metavar="N",
        type=positive_float,
        default=None,
        help="Set a timeout in seconds for waiting",
    )
    not_here(
        p, "--include-message-info", "-i", flag=True, help="Shows the associated message info."
    )


def _add_pub(v: Commands, verb: Verb) -> None:
    p = verb(
        v,
        "pub",
        "Publish a message to a topic",
        lambda c, a: pub(
            c,
            a.topic_name,
            a.message_type,
            a.values,
            once=a.once,
            rate=a.rate,
            times=a.times,
            wait_matching=a.wait_matching_subscriptions,
            print_nth=a.print,
            max_wait_time=a.max_wait_time_secs,
            keep_alive=a.keep_alive,
            qos=qos_of(a),
        ),
    )
    p.add_argument("topic_name", help="Name of the ROS topic to publish to (e.g. '/chatter')")
    p.add_argument("message_type", help="Type of the ROS message (e.g. 'std_msgs/String')")
    values_or_stdin = p.add_mutually_exclusive_group()
    values_or_stdin.add_argument(
        "values",
        nargs="?",
        default="{}",
        help="Values to fill the message with in YAML format (e.g. 'data: Hello World'), "
        "otherwise the message will be published with default values",
    )
    not_here(p, "--stdin", flag=True, group=values_or_stdin, help="Read values from standard input")
    p.add_argument(
        "-r",
        "--rate",
        metavar="N",
        type=positive_float,
        default=1.0,
        help="Publishing rate in Hz (default: 1)",
    )
    p.add_argument(
        "-p",
        "--print",
        metavar="N",
        type=int,
        default=1,
        help="Only print every N-th published message (default: 1)",
    )
    once_or_times = p.add_mutually_exclusive_group()
    once_or_times.add_argument(
        "-1", "--once", action="store_true", help="Publish one message and exit"
    )
    once_or_times.add_argument(
        "-t",
        "--times",
        type=nonnegative_int,
        default=0,
        help="Publish this number of times and then exit",
    )
    p.add_argument(
        "-w",
        "--wait-matching-subscriptions",
        type=nonnegative_int,
        default=None,
        help="Wait until finding the specified number of matching subscriptions. "
        'Defaults to 1 when using "-1"/"--once"/"--times", otherwise defaults to 0.',
    )
    p.add_argument(
        "--max-wait-time-secs",
        type=positive_float,
        default=None,
        help="This sets the maximum wait time in seconds if "
        "--wait-until-matching-subscriptions is set. By default, this flag is not set "
        "meaning the subscriber will wait endlessly.",
    )
    p.add_argument(
        "--keep-alive",
        metavar="N",
        type=positive_float,
        default=0.1,
        help="Keep publishing node alive for N seconds after the last msg (default: 0.1)",
    )
    not_here(p, "-n", "--node-name", help="Name of the created publishing node")
    qos_options(p, "publish", "default")
    spin_time(p)
