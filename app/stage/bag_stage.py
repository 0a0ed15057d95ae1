"""The newest bag on stage: what it holds, as `ros2 bag info` prints it, and when each
message was recorded, one row of ticks per topic.

The bags lesson's evidence: a recording shows up the moment it ends, its
summary beside a timeline that makes "12 s of /chatter at 2 Hz" something
to see. The folder is looked at every few seconds while the stage is shown;
reading a bag is a worker job (a large bag never stalls the page).
"""

from __future__ import annotations

import html
import time
from dataclasses import dataclass
from pathlib import Path

import viser

from app.bags.bagfile import open_bag
from app.bags.folder import bags_dir, list_bags
from app.bags.info import BagInfo, human_size, info_lines, read_info
from app.ros.graph import GraphSnapshot
from app.ui import MarkdownView, code_block
from app.ui.loop import UiLoop

LOOK_SEC = 2.0  # the bags folder is listed this often (a recording ends in the Console)
MAX_TICKS = 4000  # per topic: a longer bag draws every n-th message
WIDTH, ROW_H, LABEL_W = 760, 26, 200
NO_BAG = (
    "_No bag in your bags folder yet._ A recording (`ros2 bag record`, the step's button, "
    "or **Record › Bags**) shows here when it ends: what it holds, and when each message "
    "came."
)

BEING_RECORDED = (
    "being recorded… Its summary and timeline show when the recording ends (a recording "
    "that was killed has none: `ros2 bag reindex` rebuilds it)."
)


@dataclass(frozen=True)
class BagPicture:
    info: BagInfo
    stamps: dict[str, list[int]]  # topic -> receive times (ns), at most MAX_TICKS each


def read_bag(path: Path) -> BagPicture:
    """The bag's summary and its messages' times (BagError while it is being recorded)."""
    info = read_info(path)
    stamps: dict[str, list[int]] = {t.name: [] for t in info.topics}
    every = {t.name: max(1, -(-t.count // MAX_TICKS)) for t in info.topics}
    seen: dict[str, int] = dict.fromkeys(stamps, 0)
    with open_bag(path) as reader:
        for connection, timestamp, _raw in reader.messages():
            topic = connection.topic
            if topic in seen and seen[topic] % every[topic] == 0:
                stamps[topic].append(timestamp)
            seen[topic] = seen.get(topic, 0) + 1
    return BagPicture(info, stamps)


def timeline_svg(picture: BagPicture, cursor_ns: int | None = None) -> str:
    """One row per topic, a tick per message, seconds from the bag's start along the bottom;
    ``cursor_ns``: a red line at that moment (a recording being played)."""
    info = picture.info
    span = max(info.duration_ns, 1)
    plot_w = WIDTH - LABEL_W - 20
    rows = []
    for row, topic in enumerate(info.topics):
        y = 10 + row * ROW_H
        ticks = "".join(
            f'<line x1="{x:.1f}" y1="{y}" x2="{x:.1f}" y2="{y + ROW_H - 8}"/>'
            for stamp in picture.stamps.get(topic.name, [])
            if (x := LABEL_W + plot_w * (stamp - info.start_ns) / span) >= 0
        )
        label = html.escape(f"{topic.name} ({topic.count})")
        rows.append(
            f'<text x="{LABEL_W - 8}" y="{y + ROW_H / 2}" text-anchor="end" '
            f'dominant-baseline="middle">{label}</text><g stroke="#1c7ed6">{ticks}</g>'
        )
    axis_y = 14 + len(info.topics) * ROW_H
    seconds = info.duration_ns / 1e9
    marks = "".join(
        f'<text x="{LABEL_W + plot_w * i / 4:.1f}" y="{axis_y + 14}" text-anchor="middle">'
        f"{seconds * i / 4:.1f} s</text>"
        for i in range(5)
    )
    height = axis_y + 24
    if cursor_ns is not None:
        x = LABEL_W + plot_w * min(max(cursor_ns - info.start_ns, 0), span) / span
        marks += (
            f'<line class="cursor" x1="{x:.1f}" y1="4" x2="{x:.1f}" y2="{axis_y}" '
            'stroke="#e03131" stroke-width="2"/>'
        )
    return (
        f'<svg class="stage-bag" width="{WIDTH}" height="{height}" '
        f'viewBox="0 0 {WIDTH} {height}" font-family="sans-serif" font-size="12" '
        f'role="img" aria-label="When each message of the bag was recorded">'
        f'<line x1="{LABEL_W}" y1="{axis_y}" x2="{WIDTH - 20}" y2="{axis_y}" stroke="#868e96"/>'
        f"{''.join(rows)}{marks}</svg>"
    )


class BagStage:
    def __init__(self, gui: viser.GuiApi, ui: UiLoop) -> None:
        self._ui = ui
        self._active = False
        self._next_look = 0.0
        self._shown: tuple[Path, float] | None = None  # the bag drawn, and its mtime
        self._reading = False
        self._box = gui.add_folder("Newest bag", expand_by_default=True, visible=False)
        with self._box:
            self._heading = MarkdownView(gui, NO_BAG)
            self._timeline = gui.add_html("")
            self._timeline_svg = ""
            self._info = MarkdownView(gui, "")

    def set_active(self, active: bool) -> None:
        self._active = active
        self._box.visible = active
        self._next_look = 0.0

    def refresh(self, graph: GraphSnapshot) -> None:
        now = time.monotonic()
        if not self._active or self._reading or now < self._next_look:
            return
        self._next_look = now + LOOK_SEC
        bags = list_bags(bags_dir())
        if not bags:
            self._show_nothing()
            return
        newest = bags[0]
        key = (newest, _changed_at(newest))
        if key == self._shown:
            return
        if not (newest / "metadata.yaml").exists():  # rosbag2 writes it when a recording ends
            self._heading.show(f"**`{newest.name}`** · {BEING_RECORDED}")
            self._set_timeline("")
            self._info.show("")
            return
        self._reading = True

        def done(picture: BagPicture) -> None:
            self._reading = False
            self._shown = key
            self._show(picture)

        def failed(text: str) -> None:  # being recorded (no summary yet), or damaged
            self._reading = False
            self._heading.show(f"**`{newest.name}`** · {text}")
            self._set_timeline("")
            self._info.show("")

        self._ui.run_job(lambda: read_bag(newest), done, failed)

    def _show_nothing(self) -> None:
        self._shown = None
        self._heading.show(NO_BAG)
        self._set_timeline("")
        self._info.show("")

    def _show(self, picture: BagPicture) -> None:
        info = picture.info
        self._heading.show(
            f"**`{info.path.name}`** · {info.message_count} messages in "
            f"{info.duration_ns / 1e9:.1f} s · {human_size(info.size)} · "
            f"`ros2 bag info {info.path.name}`"
        )
        self._set_timeline(timeline_svg(picture))
        self._info.show(code_block(info_lines(info)))

    def _set_timeline(self, svg: str) -> None:
        """Sent to the page only when it changes (the folder is looked at every 2 s)."""
        if svg != self._timeline_svg:
            self._timeline_svg = svg
            self._timeline.content = svg

    def close(self) -> None:
        pass


def _changed_at(folder: Path) -> float:
    """The newest change in the bag folder (a recording's metadata is written at its end)."""
    try:
        return max((p.stat().st_mtime for p in folder.iterdir()), default=0.0)
    except OSError:
        return 0.0
