"""Echo panel: the latest messages on /chatter, as `ros2 topic echo /chatter` shows them."""

from __future__ import annotations

import time

import viser

from app.graph import GraphSnapshot
from app.panels import MarkdownView, code_block
from app.ros2cli.topic import TopicMonitor

SHOWN_MESSAGES = 10
FAST_HZ = 50.0


class EchoPanel:
    def __init__(self, gui: viser.GuiApi, tap: TopicMonitor) -> None:
        self._tap = tap
        self._view = MarkdownView(gui)

    def refresh(self, graph: GraphSnapshot | None) -> None:
        recent = self._tap.recent(SHOWN_MESSAGES)
        lines = [
            f"[{time.strftime('%H:%M:%S', time.localtime(t))}] data: {msg.data!r}"
            for t, msg in recent
        ]
        rate = self._tap.rate_hz()
        rate_text = f"{rate:.1f} Hz" if rate else "no messages lately"
        if rate and rate > FAST_HZ:  # say so: most messages scroll by unseen
            rate_text += f" · ⚠ too fast to read: showing only the newest {SHOWN_MESSAGES}"
        header = f"`ros2 topic echo {self._tap.topic}` · {self._tap.count} received · {rate_text}"
        publishers = (
            graph.topic(self._tap.topic).publishers if graph and graph.topic(self._tap.topic) else 0
        )
        hint = "" if publishers else "\n\n_No publisher on this topic: start **talker**._"
        self._view.show(header + hint + "\n\n" + code_block(lines, "(waiting for messages)"))
