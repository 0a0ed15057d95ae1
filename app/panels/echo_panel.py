"""Echo panel: the latest messages on /chatter, as `ros2 topic echo /chatter` shows them."""

from __future__ import annotations

import time

import viser
from rclpy.node import Node
from std_msgs.msg import String

from app.ros.graph import GraphSnapshot
from app.ros.monitor import TopicMonitor
from app.ui import MarkdownView, code_block

TOPIC = "/chatter"
SHOWN_MESSAGES = 10
FAST_HZ = 50.0
RATE_WINDOW_SEC = 5.0


class EchoPanel:
    def __init__(self, gui: viser.GuiApi, node: Node) -> None:
        self._tap = TopicMonitor(node, TOPIC, String, keep=50, qos=10)
        self._view = MarkdownView(gui)

    def refresh(self, graph: GraphSnapshot) -> None:
        recent = self._tap.recent(SHOWN_MESSAGES)
        lines = [
            f"[{time.strftime('%H:%M:%S', time.localtime(t))}] data: {msg.data!r}"
            for t, msg in recent
        ]
        # The publisher's rate by its own clock; samples this view missed are
        # counted, not hidden in a lower rate.
        published = self._tap.published_rate(window_sec=RATE_WINDOW_SEC)
        rate = published.rate if published else None
        rate_text = published.summary(self._tap.why_missed(), 1) if published else ""
        rate_text = rate_text or "no messages lately"
        if rate and rate > FAST_HZ:  # say so: most messages scroll by unseen
            rate_text += f" · ⚠ too fast to read: showing only the newest {SHOWN_MESSAGES}"
        header = f"`ros2 topic echo {TOPIC}` · {self._tap.count} received · {rate_text}"
        hint = (
            "" if graph.publishers(TOPIC) else "\n\n_No publisher on this topic: start **talker**._"
        )
        self._view.show(header + hint + "\n\n" + code_block(lines, "(waiting for messages)"))

    def close(self) -> None:
        self._tap.close()
