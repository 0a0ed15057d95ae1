"""The TF tree on stage: every frame under its parent, live, as `view_frames` draws it.

``ros2 run tf2_tools view_frames`` listens to ``/tf`` and ``/tf_static`` for a
few seconds and draws the tree with, on each edge, who broadcasts it, how
often and how much of it is buffered. The stage listens all the time it is
shown, through the dashboard's one TF reader (``app.ros.tf_sources``, which
the TF tool and the 3D view read too), and redraws the same picture
(tf2_tools' own drawing) each second when the tree changed: a learner who
starts a broadcaster sees its frame join the tree.

Threads: the TF reader's thread records under a lock; the stage (UI thread)
starts and stops listening, and reads.
"""

from __future__ import annotations

import re
import threading
import time
from collections import deque
from dataclasses import dataclass, field

import viser
from rclpy.node import Node
from tf2_ros._wire import Entry
from tf2_tools.frames_svg import render

from app.ros import tf_sources
from app.ros.graph import GraphSnapshot
from app.ui import MarkdownView

BUFFER_SEC = 10.0  # tf2's default cache: transforms older than this are dropped
STATIC_RATE = 10000.0  # what view_frames reports for a static transform
REDRAW_SEC = 1.0
MAX_FRAMES = 200
NOTE = (
    "Each arrow points from a parent frame to its child, with the broadcaster, rate and "
    "buffer that `ros2 run tf2_tools view_frames` writes beside it. Frames appear as "
    "broadcasters send them on `/tf` and `/tf_static`."
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

    def add(self, transforms: list[Entry], static: bool, now: float | None = None) -> None:
        """One /tf or /tf_static message's transforms, as the TF reader decodes them."""
        now = time.monotonic() if now is None else now
        with self._lock:
            for frame_id, child_frame_id, stamp_ns, _translation, _rotation in transforms:
                parent = frame_id.strip().lstrip("/")
                child = child_frame_id.strip().lstrip("/")
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
                frame.stamps.append(stamp_ns * 1e-9)
                frame.arrivals.append(now)

    def clear(self) -> None:
        with self._lock:
            self._frames.clear()
            self.version += 1

    def view_frames(self, now: float | None = None) -> dict[str, dict[str, object]]:
        """Child -> the fields view_frames prints (parent, broadcaster, rate, buffer, times)."""
        now = time.monotonic() if now is None else now
        with self._lock:
            frames = {
                child: (f.parent, f.static, list(f.stamps), list(f.arrivals))
                for child, f in self._frames.items()
            }
        out: dict[str, dict[str, object]] = {}
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


MIN_TREE_SCALE = 0.75  # the frames' names stay readable at three quarters of their size


def tf_tree_html(frames: dict[str, dict[str, object]], recorded_time: float) -> str:
    """tf2_tools' picture, on white paper in either colour scheme: shrunk to the stage's
    width down to MIN_TREE_SCALE of its size (a fifth frame cut the tree off at the edge,
    and nobody scrolls a picture sideways), a bigger tree scrolls."""
    svg = render(frames, recorded_time)
    size = re.search(r'width="([\d.]+)" height="([\d.]+)"', svg)
    if size:
        width, height = size.groups()
        least = float(width) * MIN_TREE_SCALE
        svg = svg.replace(
            size.group(0),
            f'viewBox="0 0 {width} {height}" width="100%" '
            f'style="max-width:{width}px;min-width:{least:.0f}px;height:auto" '
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
        self._sources: tf_sources.TfSources | None = None  # while shown
        self._drawn = (-1, 0.0)
        self._html = ""
        self._box = gui.add_folder(None, visible=False)
        with self._box:
            gui.add_markdown(NOTE)
            self._picture = gui.add_html(tf_tree_html({}, 0.0))
            self._count = MarkdownView(gui, "")

    def set_active(self, active: bool) -> None:
        self._box.visible = active
        if active and self._sources is None:
            sources = self._sources = tf_sources.shared(self._node)
            # A fresh /tf_static subscription hears every latched frame again; the shared
            # reader heard them already: those whose broadcaster is still here join now.
            self.recorder.add(
                [
                    (f.parent, f.frame, 0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
                    for f in sources.frames()
                    if f.static and f.parent and f.publisher_here
                ],
                static=True,
            )
            sources.on_transforms(self.recorder.add)
            self._drawn = (-1, 0.0)
        elif not active and self._sources is not None:
            self._sources.remove_sink(self.recorder.add)
            tf_sources.release(self._sources)
            self._sources = None
            self.recorder.clear()  # a later look starts afresh, as view_frames does

    def refresh(self, graph: GraphSnapshot) -> None:
        if self._sources is None:
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
