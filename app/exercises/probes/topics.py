"""What the topic probes share (registers no kind): a reader for the node's answers, waiting
for its subscription, sending one input and reading the answer to it, and why nothing came.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Protocol, TypeVar

from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile

from app.exercises.probes.base import ProbeContext, same
from app.ros.graph import subscriptions_ours_and_others
from app.ros.monitor import TopicMonitor
from app.ros.names import node_fqn
from app.ros.qos import matching_qos

if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import SupportsFloat

    from rclpy.publisher import Publisher
    from std_msgs.msg import Header

# Reaches reliable and best-effort subscribers alike.
SEND_QOS = QoSProfile(depth=10)
MATCH_WAIT_SEC = 5.0  # for the learner's subscription to appear
ANSWER_MATCH_SEC = 0.5  # once our reader matched its writer, for its writer to match ours
ANSWER_WAIT_SEC = 2.0  # for one answer to one input
RESENDS = 3  # an input is sent again when no answer came (discovery may lag)


class Stamped(Protocol):
    """A message with a ``std_msgs/msg/Header``: its stamp tells which input an answer is to."""

    header: Header


M = TypeVar("M")  # the messages of a topic (their generated class is untyped)
S = TypeVar("S", bound=Stamped)  # answers that carry a header


def split_name(fqn: str) -> tuple[str, str]:
    namespace, _, name = fqn.rpartition("/")
    return namespace or "/", name


def listen(ctx: ProbeContext, topic: str, msg_type: type[M]) -> TopicMonitor[M]:
    """A reader for the node's answers, reliable when its publisher is (big messages)."""
    qos = matching_qos(ctx.call.node, topic, depth=20)
    return TopicMonitor(ctx.call.node, topic, msg_type, keep=20, qos=qos)


def others_subscribed(node: Node, publisher: Publisher, topic: str) -> int:
    """Readers matched by ``publisher`` other than the grader's own: ``node``'s, and the
    recording of the attempt's (it subscribes to every topic: it is not the learner's node
    listening)."""
    counted, _others = subscriptions_ours_and_others(node, topic)
    return max(0, int(publisher.get_subscription_count()) - counted)


def _within(ctx: ProbeContext, timeout: float, done: Callable[[], object]) -> bool:
    """Whether ``done()`` turned true within ``timeout`` seconds, asked every 50 ms."""
    deadline = time.monotonic() + timeout
    while not done():
        if time.monotonic() > deadline:
            return False
        ctx.call.sleep(0.05)
    return True


def wait_subscribed(ctx: ProbeContext, publisher: Publisher, topic: str) -> str:
    """'' once someone subscribes to ``topic``, else why not."""
    if not _within(ctx, MATCH_WAIT_SEC, lambda: others_subscribed(ctx.call.node, publisher, topic)):
        return f"nothing subscribes to {topic} (waited {MATCH_WAIT_SEC:g} s)"
    ctx.call.sleep(0.3)  # let the learner's publisher find our reader too
    return ""


def wait_delivered(
    ctx: ProbeContext, publisher: Publisher, timeout: float = MATCH_WAIT_SEC
) -> bool:
    """Whether every reliable subscription matched to ``publisher`` acknowledged all it
    sent, a latched message included: True as soon as they did, False after ``timeout``.
    Polled with a zero wait each time: a long wait sits in native code, which may keep
    the GIL from the dashboard's other threads (the grader runs in its process)."""
    return _within(ctx, timeout, lambda: publisher.wait_for_all_acked(Duration(seconds=0)))


def wait_matched(ctx: ProbeContext, ours: Sequence[tuple[Publisher, str]], theirs: str) -> str:
    """'' once the node subscribes to each of ``ours`` (publisher, topic), else why not; then
    up to a second more for its publisher on ``theirs`` to show (it may have none: the
    grading then says so), and a little for its writer to match our reader."""
    node = ctx.call.node

    def missing() -> list[str]:
        return [topic for pub, topic in ours if not others_subscribed(node, pub, topic)]

    if not _within(ctx, MATCH_WAIT_SEC, lambda: not missing()) and (still := missing()):
        return f"nothing subscribes to {still[0]} (waited {MATCH_WAIT_SEC:g} s)"
    _within(ctx, 1.0, lambda: node.count_publishers(theirs))
    ctx.call.sleep(0.1)
    return ""


def wait_answering(ctx: ProbeContext, monitor: TopicMonitor, timeout: float = 3.0) -> None:
    """Wait until the node's publisher on ``monitor``'s topic is matched with our reader (it
    may have none: the grading then says so), then a little for its writer to match us in
    turn. The ROS graph shows a publisher well before that on a loaded machine, and what
    it sends before is lost (CI: the first three of seven answers)."""
    _within(ctx, timeout, monitor.matched_publishers)
    ctx.call.sleep(ANSWER_MATCH_SEC)


def exchange(
    ctx: ProbeContext,
    publisher: Publisher,
    monitor: TopicMonitor[S],
    message: Stamped,
    stamp_sec: int,
) -> S | None:
    """Send ``message`` stamped ``stamp_sec`` s and return the answer to it, or None.

    An answer with our stamp belongs to this input. One with a zero stamp (a
    node that does not copy the header) is taken as the answer to the newest
    input. Any other stamp (a late answer to an earlier input, or to someone
    else's) is skipped.
    """
    message.header.stamp.sec, message.header.stamp.nanosec = stamp_sec, 0
    seen = monitor.count
    for _ in range(RESENDS):
        publisher.publish(message)
        deadline = time.monotonic() + ANSWER_WAIT_SEC
        while time.monotonic() < deadline:
            monitor.wait_for_count(seen + 1, 0.1)
            ctx.call.check_cancel()
            for _arrival, answer in monitor.messages_since(seen):
                seen += 1
                stamp = answer.header.stamp
                if stamp.sec == stamp_sec or (stamp.sec == 0 and stamp.nanosec == 0):
                    return answer
    return None


def fmt(values: Iterable[SupportsFloat]) -> str:
    return "(" + ", ".join(f"{float(v):.3f}" for v in values) + ")"


def profile_text(qos: QoSProfile) -> str:
    """'best_effort, volatile' for a profile."""
    return f"{qos.reliability.name.lower()}, {qos.durability.name.lower()}"


def publishers_note(node: Node, topic: str, type_text: str, durability: str = "") -> str:
    """Why nothing may have arrived: no publisher, another type, or volatile history."""
    infos = node.get_publishers_info_by_topic(topic)
    if not infos:
        return f"nothing publishes on {topic}"
    types = sorted({info.topic_type for info in infos})
    if type_text not in types:
        return f"{topic} is published as {', '.join(types)}, not {type_text}"
    if durability == "transient_local":
        volatile = [
            node_fqn(i.node_name, i.node_namespace)
            for i in infos
            if i.qos_profile.durability != DurabilityPolicy.TRANSIENT_LOCAL
        ]
        if volatile:
            return (
                f"{', '.join(volatile)} publishes with volatile durability: it keeps nothing "
                "for a subscriber that joins later"
            )
    return ""


def with_note(text: str, note: str) -> str:
    return f"{text} ({note})" if note else text


def difference(actual: object, expected: object, tolerance: float, path: str) -> str:
    """'' when ``actual`` has every expected field (deeply), else the first that differs."""
    if isinstance(expected, dict):
        if not isinstance(actual, dict):
            return f"{path} = {actual!r}, expected {expected!r}"
        for key, want in expected.items():
            where = f"{path}.{key}" if path else key
            if key not in actual:
                return f"the message has no field {where}"
            found = difference(actual[key], want, tolerance, where)
            if found:
                return found
        return ""
    if same(actual, expected, tolerance):
        return ""
    return f"{path} = {actual!r}, expected {expected!r}"
