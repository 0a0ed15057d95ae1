"""What the TF checks share: one listener on /tf and /tf_static per lesson runtime.

The TF checks (``tf_frame``, ``tf_transform``, ``tf_moves``, ``tf_late_joiner``)
judge the transform tree as a learner's own listener would see it, so they
read it through our ``tf2_ros.Buffer``: lookups chain frames, interpolate and
raise tf2's own exceptions. Beside the buffer the watch keeps what a buffer
does not say plainly: each frame's parent, and whether it came on /tf_static.

One watch per ``LessonRuntime`` (created on first use, on the runtime's
node, closed once no check reads it): the subscriptions' callbacks run on the
executor thread and only store; checks read under the lock and never block.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rclpy.node import Node
from tf2_msgs.msg import TFMessage
from tf2_ros import Buffer

from app.ros.tf_sources import STATIC_QOS, TF_QOS

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime


@dataclass
class HeardFrame:
    """One child frame as the watch last heard it."""

    parent: str
    static: bool
    updates: int = 0
    last_seen: float = field(default_factory=time.monotonic)


class TfWatch:
    """/tf and /tf_static into a tf2 Buffer, plus each frame's parent and kind."""

    def __init__(self, node: Node) -> None:
        self.node = node
        self.buffer = Buffer()
        self.lock = threading.Lock()
        self.frames: dict[str, HeardFrame] = {}
        # Per check key: what a check remembers between calls (each check knows its own).
        self.memory: dict[str, object] = {}
        self._subscriptions = [
            node.create_subscription(TFMessage, "/tf", self._on_tf, TF_QOS),
            node.create_subscription(TFMessage, "/tf_static", self._on_static, STATIC_QOS),
        ]

    def _store(self, msg: TFMessage, static: bool) -> None:
        for t in msg.transforms:
            if static:
                self.buffer.set_transform_static(t, "lesson_check")
            else:
                self.buffer.set_transform(t, "lesson_check")
            with self.lock:
                info = self.frames.get(t.child_frame_id)
                if info is None or info.parent != t.header.frame_id or info.static != static:
                    info = self.frames[t.child_frame_id] = HeardFrame(t.header.frame_id, static)
                info.updates += 1
                info.last_seen = time.monotonic()

    def _on_tf(self, msg: TFMessage) -> None:
        self._store(msg, static=False)

    def _on_static(self, msg: TFMessage) -> None:
        self._store(msg, static=True)

    def frame(self, name: str) -> HeardFrame | None:
        with self.lock:
            info = self.frames.get(name)
            return None if info is None else HeardFrame(**vars(info))

    def known(self) -> list[str]:
        with self.lock:
            return sorted(self.frames)

    def close(self) -> None:
        """Destroy the watch's subscriptions and any a check made (late joiners)."""
        extra = [m["joiner"].subscription for m in self.memory.values() if isinstance(m, dict)
                 and getattr(m.get("joiner"), "subscription", None) is not None]  # fmt: skip
        for subscription in [*self._subscriptions, *extra]:
            try:
                self.node.destroy_subscription(subscription)
            except Exception:  # the node is gone already: nothing left to free
                pass
        self._subscriptions = []
        self.memory.clear()

    def all_static(self, *frames: str) -> bool:
        """Whether every frame from these up to their roots came on /tf_static."""
        with self.lock:
            for frame in frames:
                seen: set[str] = set()
                while frame in self.frames and frame not in seen:
                    seen.add(frame)
                    if not self.frames[frame].static:
                        return False
                    frame = self.frames[frame].parent
        return True

    def parent_of_others(self, name: str) -> list[str]:
        """The children that name ``name`` as their parent."""
        with self.lock:
            return sorted(child for child, info in self.frames.items() if info.parent == name)


def watch_of(rt: LessonRuntime) -> TfWatch:
    """The runtime's TF watch, subscribed on its node at the first TF check; the runtime
    closes it once no check reads it."""
    return rt.watch("tf", TfWatch)


def nobody_publishes(rt: LessonRuntime) -> bool:
    """No publisher on /tf nor /tf_static in the graph snapshot."""
    return not rt.publishers("/tf") and not rt.publishers("/tf_static")


def known_text(watch: TfWatch) -> str:
    names = watch.known()
    if not names:
        return "no frames heard yet"
    shown = ", ".join(names[:12]) + (", ..." if len(names) > 12 else "")
    return f"frames heard: {shown}"
