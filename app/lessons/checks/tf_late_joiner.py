"""Check ``tf_late_joiner``: a static frame reaches a subscriber that joined late.

tf2 promises every static frame to a listener that starts at any time: a
static broadcaster publishes on /tf_static with transient-local durability,
and the middleware hands the kept message to each new reader. This check
joins late on purpose: once a publisher has been on /tf_static for a moment,
it creates a fresh reliable, transient-local subscription and waits for the
frame on it. A volatile publisher, or one whose later sends replaced the
frame, leaves that subscriber without it, and the check fails with why.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, TypedDict, cast

from rclpy.subscription import Subscription
from tf2_msgs.msg import TFMessage

from app.lessons.checks._tf_watch import watch_of
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check
from app.ros.tf_sources import STATIC_QOS

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

JOIN_AFTER_SEC = 1.0  # the publisher is up this long before the subscriber joins
# Fast DDS hands history to a late joiner after about 3-4 s (its heartbeat).
DEFAULT_WITHIN_SEC = 8.0


@dataclass
class LateJoiner:
    """A fresh /tf_static subscription and the frames (child -> parent) it received."""

    subscription: Subscription | None  # made once the joiner is there to be called
    joined: float = field(default_factory=time.monotonic)
    frames: dict[str, str] = field(default_factory=dict)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def on_message(self, msg: TFMessage) -> None:
        with self.lock:
            for t in msg.transforms:
                self.frames[t.child_frame_id] = t.header.frame_id

    def parent_of(self, frame: str) -> str | None:
        with self.lock:
            return self.frames.get(frame)


class _Memory(TypedDict, total=False):
    """What the check keeps between evaluations (in the TF watch's memory)."""

    publisher_seen: float
    joiner: LateJoiner


@register_check(
    "tf_late_joiner",
    required="frame",
    optional="parent within",
    words="a static frame reaches a subscriber that joins /tf_static late "
    "(transient-local durability keeps it for late joiners)",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    watch = watch_of(rt)
    frame, parent = c["frame"], c.get("parent")
    if not rt.publishers("/tf_static"):
        watch.memory.pop(c.key, None)
        return CheckResult(FAIL, "nobody publishes /tf_static")
    memory = cast(_Memory, watch.memory.setdefault(c.key, {"publisher_seen": time.monotonic()}))
    if time.monotonic() - memory["publisher_seen"] < JOIN_AFTER_SEC:
        return CheckResult(WAITING, "a publisher is on /tf_static; joining late in a moment")
    joiner = memory.get("joiner")
    if joiner is None:
        joiner = LateJoiner(subscription=None)
        joiner.subscription = rt.node.create_subscription(
            TFMessage, "/tf_static", joiner.on_message, STATIC_QOS
        )
        memory["joiner"] = joiner
    got = joiner.parent_of(frame)
    waited = time.monotonic() - joiner.joined
    if got is not None and (parent is None or got == parent):
        return CheckResult(PASS, f"a subscriber that joined late got '{got}' -> '{frame}'")
    within = float(c.get("within", DEFAULT_WITHIN_SEC))
    if waited < within:
        return CheckResult(WAITING, f"a late subscriber has waited {waited:.0f} s for '{frame}'")
    # Give up on this subscriber; the next evaluation joins afresh.
    assert joiner.subscription is not None  # made with the joiner, above
    rt.node.destroy_subscription(joiner.subscription)
    watch.memory.pop(c.key, None)
    if got is not None:
        return CheckResult(
            FAIL, f"a late subscriber got '{frame}' with the parent '{got}'; expected '{parent}'"
        )
    heard = f" (it got: {', '.join(sorted(joiner.frames))})" if joiner.frames else ""
    return CheckResult(
        FAIL,
        f"a subscriber that joined /tf_static late got no '{frame}' in {within:g} s{heard}: "
        "a static frame must be published transient local (StaticTransformBroadcaster does "
        "this) and kept in the latest message",
    )
