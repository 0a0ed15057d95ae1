"""The TF tree on stage: every frame under its parent, live, as `view_frames` draws it.

``ros2 run tf2_tools view_frames`` listens to ``/tf`` and ``/tf_static`` for a
few seconds and draws the tree with, on each edge, who broadcasts it, how
often and how much of it is buffered. The stage listens the same way, all the
time it is shown, and redraws the same picture (tf2_tools' own drawing) each
second when the tree changed: a learner who starts a broadcaster sees its
frame join the tree.

Threads: the subscriptions (executor thread) record under a lock; the stage
(UI thread) subscribes, unsubscribes and reads.
"""

from __future__ import annotations

import re
import threading
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

import viser
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile
from rclpy.subscription import Subscription
from tf2_msgs.msg import TFMessage
from tf2_tools.frames_svg import render

from app.ros.graph import GraphSnapshot
from app.ui import MarkdownView

TF_QOS = QoSProfile(depth=100)
STATIC_QOS = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL)
BUFFER_SEC = 10.0  # tf2's default cache: transforms older than this are dropped
STATIC_RATE = 10000.0  # what view_frames reports for a static transform
REDRAW_SEC = 1.0
MAX_FRAMES = 200
NOTE = (
    "Each arrow points from a parent frame to its child, labelled as `ros2 run tf2_tools "
    "view_frames` labels it. Frames appear as broadcasters send them on `/tf` and "
    "`/tf_static`."
)


@dataclass
class _Frame:
    parent: str
    static: bool
    stamps: deque[float] = field(default_factory=lambda: deque(maxlen=500))  # message times
    arrivals: deque[float] = field(default_factory=lambda: deque(maxlen=100))  # our clock


class TfRecorder:
    """What view_frames' buffer knows of each frame; ``add`` from any thread."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._frames: dict[str, _Frame] = {}
        self.version = 0

    def add(self, msg: TFMessage, static: bool, now: float | None = None) -> None:
        now = time.monotonic() if now is None else now
        with self._lock:
            for t in msg.transforms:
                parent = t.header.frame_id.strip().lstrip("/")
                child = t.child_frame_id.strip().lstrip("/")
                if not parent or not child or parent == child:
                    continue  # tf2 ignores these too
                frame = self._frames.get(child)
                if frame is None:
                    if len(self._frames) >= MAX_FRAMES:
                        continue
                    frame = self._frames[child] = _Frame(parent, static)
                if frame.parent != parent or frame.static != static:
                    self.version += 1  # the tree changed shape
                frame.parent, frame.static = parent, static
                frame.stamps.append(t.header.stamp.sec + t.header.stamp.nanosec * 1e-9)
                frame.arrivals.append(now)

    def clear(self) -> None:
        with self._lock:
            self._frames.clear()
            self.version += 1

    def view_frames(self, now: float | None = None) -> dict[str, dict[str, Any]]:
        """Child -> the fields view_frames prints (parent, broadcaster, rate, buffer, times)."""
        now = time.monotonic() if now is None else now
        with self._lock:
            frames = {
                child: (f.parent, f.static, list(f.stamps), list(f.arrivals))
                for child, f in self._frames.items()
            }
        out: dict[str, dict[str, Any]] = {}
        for child, (parent, static, stamps, arrivals) in sorted(frames.items()):
            recent = [t for t in arrivals if now - t <= BUFFER_SEC]
            if static:
                rate = STATIC_RATE
            elif len(recent) >= 2 and recent[-1] > recent[0]:
                rate = round((len(recent) - 1) / (recent[-1] - recent[0]), 3)
            else:
                rate = 0.0
            newest = max(stamps) if stamps else 0.0
            kept = [s for s in stamps if newest - s <= BUFFER_SEC] or [newest]
            out[child] = {
                "parent": parent,
                "broadcaster": "default_authority",  # what rclpy's broadcasters send
                "rate": rate,
                "buffer_length": 0.0 if static else round(newest - min(kept), 3),
                "most_recent_transform": 0.0 if static else round(newest, 6),
                "oldest_transform": 0.0 if static else round(min(kept), 6),
            }
        return out


def tf_tree_html(frames: dict[str, dict[str, Any]], recorded_time: float) -> str:
    """tf2_tools' picture at its natural size (never shrunk: its labels stay readable; a
    big tree scrolls), on white paper in either colour scheme."""
    svg = render(frames, recorded_time)
    size = re.search(r'width="([\d.]+)" height="([\d.]+)"', svg)
    if size:
        width, height = size.groups()
        svg = svg.replace(
            size.group(0),
            f'viewBox="0 0 {width} {height}" width="{width}" height="{height}" '
            f'role="img" aria-label="TF tree: {len(frames)} frames"',
            1,
        )
    return (
        '<div class="stage-tf" style="background:#fff;color:#000;border-radius:4px;'
        f'padding:6px;overflow:auto">{svg}</div>'
    )


class TfStage:
    """Built inside the stage window's tab; ``refresh`` and ``set_active`` on the UI thread."""

    def __init__(self, gui: viser.GuiApi, node: Node) -> None:
        self._node = node
        self.recorder = TfRecorder()
        self._subs: list[Subscription] = []
        self._drawn = (-1, 0.0)
        self._html = ""
        self._box = gui.add_folder(None, visible=False)
        with self._box:
            gui.add_markdown(NOTE)
            self._picture = gui.add_html(tf_tree_html({}, 0.0))
            self._count = MarkdownView(gui, "")

    def set_active(self, active: bool) -> None:
        self._box.visible = active
        if active and not self._subs:
            record = self.recorder.add
            self._subs = [
                self._node.create_subscription(
                    TFMessage, "/tf", lambda m: record(m, False), TF_QOS
                ),
                self._node.create_subscription(
                    TFMessage, "/tf_static", lambda m: record(m, True), STATIC_QOS
                ),
            ]
            self._drawn = (-1, 0.0)
        elif not active and self._subs:
            for sub in self._subs:
                self._node.destroy_subscription(sub)
            self._subs = []
            self.recorder.clear()  # a later look starts afresh, as view_frames does

    def refresh(self, graph: GraphSnapshot) -> None:
        if not self._subs:
            return
        now = time.monotonic()
        version, drawn_at = self._drawn
        if self.recorder.version == version and now - drawn_at < REDRAW_SEC:
            return
        self._drawn = (self.recorder.version, now)
        frames = self.recorder.view_frames(now)
        html = tf_tree_html(frames, round(time.time(), 3))
        if html != self._html:
            self._html = html
            self._picture.content = html
        names = sorted(set(frames) | {str(f["parent"]) for f in frames.values()})
        self._count.show(
            f"**{len(names)} frames**: " + ", ".join(f"`{n}`" for n in names) if names else ""
        )

    def close(self) -> None:
        self.set_active(False)
