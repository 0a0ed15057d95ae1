"""TF panel: the transform tree as tf2 sees it, who broadcasts each frame, and tf2_echo.

What rviz's TF display, ``view_frames``, ``tf2_monitor`` and ``tf2_echo``
tell a ROS user, in one tab: every frame under its parent, each with its
publisher node, rate, age, static or dynamic, and stale frames said in words;
a tf2_echo readout (a real tf2 lookup) for two frames the learner picks;
and the picture the last ``ros2 run tf2_tools view_frames`` drew.

Data comes from ``app.ros.tf_sources`` (its own thread); this panel reads
copies on the UI thread and never waits on ROS.
"""

from __future__ import annotations

import base64
import re
from collections import defaultdict
from pathlib import Path

import viser
from rclpy.node import Node
from rclpy.time import Time
from tf2_ros import TransformException
from tf2_ros.tools.tf2_echo import format_transform

from app.ros import tf_sources
from app.ros.graph import GraphSnapshot
from app.ros.tf_sources import FrameInfo, TfSources
from app.supervisor import Supervisor
from app.ui import MarkdownView, assign, code_block, set_options
from app.ui.loop import UiLoop

INTRO = (
    "Every frame on `/tf` and `/tf_static`, each under its parent, as tf2 sees it: who "
    "broadcasts it, how often, how long ago, and whether it is static. Frames whose "
    "publisher went quiet are marked **stale**."
)
PICK = "(pick a frame)"
VIEW_FRAMES = "view_frames"  # the catalog program `ros2 run tf2_tools view_frames` starts
PICTURE_LINE = re.compile(r"^view_frames: the picture is (/\S+/frames_[\w.\-]+\.svg)$")
MAX_PICTURE_BYTES = 2_000_000


def _age(seconds: float) -> str:
    return f"{seconds:.1f} s" if seconds < 120 else f"{seconds / 60:.0f} min"


def _first_line(text: str) -> str:
    return text.splitlines()[0] if text else ""


def _rate(hz: float) -> str:
    """Whole hertz from 10 Hz up: the text (re-sent on change) does not flicker."""
    return f"{hz:.0f} Hz" if hz >= 10 else f"{hz:.1f} Hz"


def describe(frame: FrameInfo) -> str:
    """One frame's line of the tree, in words a beginner can read."""
    name = f"**`{frame.frame}`**"
    if not frame.parent:
        return f"{name} · root (no parent)"
    parts = [name, f"parent `{frame.parent}`"]
    if frame.static:
        parts.append(f"static (latched on /tf_static, sent {_age(frame.age)} ago)")
    elif frame.stale:
        parts.append(f"dynamic · ⚠️ **STALE**: no transform for {_age(frame.age)}")
    else:
        rate = _rate(frame.rate) if frame.rate else "rate not known yet"
        parts.append(f"dynamic · {rate} · last {_age(frame.age)} ago")
    if not frame.publisher:
        parts.append("publisher not known yet")
    elif frame.publisher_here:
        parts.append(f"by `{frame.publisher}`")
    elif frame.static:
        parts.append(
            f"by `{frame.publisher}` (publisher gone: listeners started from now on will not "
            "get it)"
        )
    else:
        parts.append(f"by `{frame.publisher}` (that publisher is gone)")
    line = " · ".join(parts)
    if frame.conflict:
        line += f" · ⚠️ **two parents**: {frame.conflict} (tf2 warns TF_PARENT_CHANGED)"
    return line


def tree_markdown(frames: list[FrameInfo]) -> str:
    """The tree as a nested Markdown list: each frame under its parent."""
    if not frames:
        return "No TF frames yet: nothing on `/tf` or `/tf_static`."
    children: dict[str, list[FrameInfo]] = defaultdict(list)
    for frame in frames:
        if frame.parent:
            children[frame.parent].append(frame)
    lines: list[str] = []
    seen: set[str] = set()

    def walk(frame: FrameInfo, depth: int) -> None:
        if frame.frame in seen:
            return
        seen.add(frame.frame)
        lines.append("  " * depth + "- " + describe(frame))
        for child in sorted(children[frame.frame], key=lambda f: f.frame):
            walk(child, depth + 1)

    for root in (f for f in frames if not f.parent):
        walk(root, 0)
    looped = sorted(f.frame for f in frames if f.frame not in seen)
    if looped:
        lines.append(
            "- ⚠️ In a loop, so in no tree (TF must be a tree): "
            + ", ".join(f"`{name}`" for name in looped)
        )
    roots = sum(1 for f in frames if not f.parent)
    static = sum(1 for f in frames if f.parent and f.static)
    dynamic = sum(1 for f in frames if f.parent and not f.static)
    stale = sum(1 for f in frames if f.stale)
    summary = (
        f"{len(frames)} frames in {roots} tree{'s' if roots != 1 else ''} · {static} static, "
        f"{dynamic} dynamic" + (f" · ⚠️ {stale} stale" if stale else "")
    )
    return summary + "\n\n" + "\n".join(lines)


def stale_between(frames: list[FrameInfo], target: str, source: str) -> list[str]:
    """Stale frames on the way from either frame up to its root (the lookup's chain)."""
    by_name = {f.frame: f for f in frames}
    found: list[str] = []
    for start in (target, source):
        frame, seen = by_name.get(start), set()
        while frame is not None and frame.frame not in seen:
            seen.add(frame.frame)
            if frame.stale and frame.frame not in found:
                found.append(frame.frame)
            frame = by_name.get(frame.parent)
    return found


def echo_markdown(
    sources: TfSources, target: str, source: str, stale: list[str] | None = None
) -> str:
    """What ``tf2_echo target source`` prints, from a tf2 lookup in the panel's buffer."""
    command = f"`ros2 run tf2_ros tf2_echo {target} {source}`"
    where = (
        f"where `{source}` is, seen from `{target}`: "
        f"`buffer.lookup_transform('{target}', '{source}', Time())`"
    )
    try:
        transform = sources.buffer.lookup_transform(target, source, Time())
    except TransformException as exc:
        return f"{command} would wait: tf2 says {type(exc).__name__}: {exc}"
    note = (
        "\n\n⚠️ " + ", ".join(f"`{name}`" for name in stale) + " went stale: with time zero tf2 "
        "answers with the last transform it got, however old (see the time stamp)."
        if stale
        else ""
    )
    block = code_block(format_transform(transform).splitlines())
    return f"{command} prints {where}\n\n{block}{note}"


def default_pair(frames: list[FrameInfo]) -> tuple[str, str]:
    """A first pair to show: a root and the frame furthest below it."""
    parents = {f.frame: f.parent for f in frames if f.parent}
    best: tuple[int, str, str] = (0, "", "")
    for frame in sorted(parents):
        depth, top, seen = 0, frame, set()
        while top in parents and top not in seen:
            seen.add(top)
            top = parents[top]
            depth += 1
        if depth > best[0]:
            best = (depth, top, frame)
    return best[1], best[2]


def picture_path(lines: list[str]) -> Path | None:
    """The SVG the newest view_frames run says it drew, if any."""
    for line in reversed(lines):
        found = PICTURE_LINE.match(line.strip())
        if found:
            return Path(found[1])
    return None


def picture_html(svg: bytes, name: str) -> str:
    """The picture as an <img>: an SVG shown this way runs no script."""
    data = base64.b64encode(svg).decode("ascii")
    return (
        f'<img alt="view_frames: {name}" title="{name}" src="data:image/svg+xml;base64,{data}" '
        'style="width:100%;background:#fff;border:1px solid #ddd;border-radius:4px"/>'
    )


class TfPanel:
    calm = True  # once a second while idle (app.ui.Panel): a tree of frames

    def __init__(self, gui: viser.GuiApi, ui: UiLoop, node: Node, supervisor: Supervisor) -> None:
        self._ui = ui
        self._supervisor = supervisor
        self.sources = tf_sources.shared(node)  # the 3D view reads the same
        MarkdownView(gui, INTRO)
        self._tree = MarkdownView(gui)
        self._how = MarkdownView(gui)
        with gui.add_folder("tf2_echo: one transform"):
            MarkdownView(
                gui,
                "Pick two frames: the readout is a tf2 lookup, printed as `tf2_echo` prints it "
                "(translation, rotation as quaternion and roll-pitch-yaw, the 4×4 matrix).",
            )
            self._options: tuple[str, ...] = (PICK,)
            self._target = gui.add_dropdown(
                "Target frame", self._options, initial_value=PICK,
                hint="tf2_echo's first frame: the answer is written in this frame",
            )  # fmt: skip
            self._source = gui.add_dropdown(
                "Source frame", self._options, initial_value=PICK,
                hint="tf2_echo's second frame: the one whose pose you want",
            )  # fmt: skip
            self._echo = MarkdownView(gui)
        with gui.add_folder("Last view_frames"):
            self._frames_note = MarkdownView(
                gui,
                "Run `ros2 run tf2_tools view_frames` in the Console: after its 5 s of "
                "listening, the tree it draws shows here.",
            )
            self._picture = gui.add_html("")
        self._picked = False
        # The pair the panel itself put in the dropdowns: any other pair was the
        # learner's, even when their pick reaches refresh before its callback.
        self._auto_pair = (PICK, PICK)
        self._shown_picture: tuple[Path, float] | None = None
        self._target.on_update(ui.callback(self._on_pick))
        self._source.on_update(ui.callback(self._on_pick))

    def _on_pick(self) -> None:
        self._picked = True

    def refresh(self, graph: GraphSnapshot) -> None:
        frames = self.sources.frames()
        problem = self.sources.buffer.last_problem
        self._tree.show(
            tree_markdown(frames) + (f"\n\n⚠️ tf2 says: {_first_line(problem)}" if problem else "")
        )
        self._how.show(
            "Publishers: each message's sender (its DDS writer) looked up in the ROS graph."
            if self.sources.exact
            else "Publishers: named by topic (this middleware does not say who sent a message)."
        )
        names = tuple(f.frame for f in frames)
        options = (PICK, *names)
        if options != self._options:
            self._options = options
            set_options(self._target, list(options))
            set_options(self._source, list(options))
        if (str(self._target.value), str(self._source.value)) != self._auto_pair:
            self._picked = True
        if not self._picked:  # until the learner picks, follow the deepest frame
            target, source = default_pair(frames)
            if target and self._auto_pair != (target, source):
                self._auto_pair = (target, source)
                assign(self._target, target)
                assign(self._source, source)
        target, source = str(self._target.value), str(self._source.value)
        if PICK in (target, source):
            self._echo.show("Pick a target and a source frame.")
        else:
            stale = stale_between(frames, target, source)
            self._echo.show(echo_markdown(self.sources, target, source, stale))
        self._show_picture()

    def _show_picture(self) -> None:
        path = picture_path(self._supervisor.output(VIEW_FRAMES, last=40))
        if path is None:
            return
        try:
            stat = path.stat()
            if stat.st_size > MAX_PICTURE_BYTES:
                raise ValueError(f"{stat.st_size} bytes is more than the panel shows")
            key = (path, stat.st_mtime)
            if key == self._shown_picture:
                return
            svg = path.read_bytes()
        except (OSError, ValueError) as exc:
            self._frames_note.show(f"⚠️ The view_frames picture `{path}` cannot be shown: {exc}")
            return
        self._shown_picture = key
        self._picture.content = picture_html(svg, path.name)
        self._frames_note.show(
            f"`{path.name}` (and `{path.with_suffix('.gv').name}`, its graphviz source), "
            f"written by the last `view_frames` in `{path.parent}`:"
        )

    def close(self) -> None:
        tf_sources.release(self.sources)
