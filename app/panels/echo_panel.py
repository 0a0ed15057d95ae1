"""Echo panel: the latest messages on a topic, as `ros2 topic echo <topic>` shows them.

/chatter until the learner clicks another topic on the stage graph.
"""

from __future__ import annotations

import time

import viser
from rclpy.node import Node
from std_msgs.msg import String

from app.panels.graph_svg import HEAVY_TYPES
from app.ros.convert import ConversionError, import_type, to_yaml
from app.ros.graph import GraphSnapshot
from app.ros.monitor import TopicMonitor
from app.ui import MarkdownView, code_block

TOPIC = "/chatter"
SHOWN_MESSAGES = 10
FAST_HZ = 50.0
RATE_WINDOW_SEC = 5.0
RATE_REFRESH_SEC = 1.0  # the rate is measured anew once a second, as `ros2 topic hz` prints
MAX_LINES = 40  # of one message's YAML


def message_text(msg: object) -> str:
    """One message as echo prints it: `data: '...'` for a string, YAML otherwise."""
    if isinstance(msg, String):
        return f"data: {msg.data!r}"
    text = to_yaml(msg).rstrip()
    lines = text.splitlines()
    return "\n".join(lines[:MAX_LINES] + (["…"] if len(lines) > MAX_LINES else []))


class EchoPanel:
    def __init__(self, gui: viser.GuiApi, node: Node) -> None:
        self._node = node
        self._topic = TOPIC
        self._note = ""
        self._tap = TopicMonitor(node, TOPIC, String, keep=50, qos=10)
        self._view = MarkdownView(gui)
        # The lines as of (tap, messages received): a pass with no new message formats
        # nothing again (issue 43's idle CPU; deserializing ten messages 5 times a second).
        self._lines_key: tuple[object, int] | None = None
        self._lines: list[str] = []
        self._rate_of: object = None  # the tap the rate was measured on, redone each second
        self._rate_at = 0.0
        self._rate_text = ""

    def inspect(self, kind: str, topic: str, type_text: str) -> None:
        """A topic clicked on the stage graph (UI thread): echo it instead."""
        if kind != "topic" or topic == self._topic or not type_text:
            return
        if type_text in HEAVY_TYPES:
            self._note = f"`{topic}` carries {type_text}: see it in **See › 3D view**."
            return
        try:
            msg_type = import_type(type_text, "msg")
        except ConversionError as exc:
            self._note = f"⚠ {exc}"
            return
        old, self._note = self._tap, ""
        self._tap = TopicMonitor(self._node, topic, msg_type, keep=50, qos=10)
        self._topic = topic
        old.close()

    def refresh(self, graph: GraphSnapshot) -> None:
        topic = self._topic
        key = (self._tap, self._tap.count)
        if key != self._lines_key:
            self._lines_key = key
            self._lines = [
                f"[{time.strftime('%H:%M:%S', time.localtime(t))}] {message_text(msg)}"
                for t, msg in self._tap.recent(SHOWN_MESSAGES)
            ]
        lines = self._lines
        now = time.monotonic()
        if self._tap is not self._rate_of or now - self._rate_at >= RATE_REFRESH_SEC:
            self._rate_of, self._rate_at = self._tap, now
            self._rate_text = self._rate_summary()
        header = f"`ros2 topic echo {topic}` · {self._tap.count} received · {self._rate_text}"
        hint = ""
        if not graph.publishers(topic):
            start = " start **talker**." if topic == TOPIC else " start one."
            hint = f"\n\n_No publisher on this topic:{start}_"
        pick = "\n\n_Click another topic on the stage graph to echo it._"
        note = f"\n\n{self._note}" if self._note else ""
        self._view.show(
            header + hint + note + "\n\n" + code_block(lines, "(waiting for messages)") + pick
        )

    def _rate_summary(self) -> str:
        # The publisher's rate by its own clock; samples this view missed are
        # counted, not hidden in a lower rate.
        published = self._tap.published_rate(window_sec=RATE_WINDOW_SEC)
        rate = published.rate if published else None
        rate_text = published.summary(self._tap.why_missed(), 1) if published else ""
        rate_text = rate_text or "no messages lately"
        if rate and rate > FAST_HZ:  # say so: most messages scroll by unseen
            rate_text += f" · ⚠ too fast to read: showing only the newest {SHOWN_MESSAGES}"
        return rate_text

    def close(self) -> None:
        self._tap.close()
