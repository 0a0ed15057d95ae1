"""A recording played on stage: the robot's way or turtlesim's window seen from above, or
each topic's messages.

"Watch this attempt" beside a grading's result opens its bag here (any bag
can be opened: a graded attempt is one). A bag of the simulated world plays
as a top view: the room, the way the robot really went so far (one line per
trial: the grader resets the world between them), the robot now and what its
scan saw now. A bag of turtlesim's poses plays as its window: the 11.09 m
square on turtlesim's blue, each turtle where its pose put it, with its trail
so far. Any other bag plays as its messages' timeline, with the newest
messages at the cursor as text: what the grader sent and what the node
answered, and when. The same play/pause, speed and time slider drive all
three (one ``ReplayStage``; the teacher page plays a learner's attempt with it
too).

Threads: reading the bag is a worker job (``app.bags.replay.read_track``);
everything else runs on the UI thread, one frame per refresh while playing.
"""

from __future__ import annotations

import html
import math
import textwrap
import time
from pathlib import Path

import viser

from app.bags.replay import Pose, Track, read_track
from app.ros.graph import GraphSnapshot
from app.ros.planar import Box
from app.stage.bag_stage import BagPicture, timeline_svg
from app.ui import MarkdownView, assign, code_block
from app.ui.loop import UiLoop
from nodes.common.turtlesim_world import DEFAULT_BACKGROUND, METER, WORLD_SIZE

WIDTH, HEIGHT = 760, 560  # px of the top view
MARGIN_M = 0.3  # m around what is drawn
SPEEDS = {"¼×": 0.25, "½×": 0.5, "1×": 1.0, "2×": 2.0, "4×": 4.0}
LINES_AT_CURSOR = 8  # messages listed under the picture
WAY_STEP_PX = 2.0  # a drawn way's points at least this far apart (a long run stays small)
ROBOT_RADIUS_M = 0.17
CAPTION_CHAR_PX = 6.6  # a 12 px sans-serif character, about: the caption wraps to the picture
CAPTION_LINE_PX = 16
TRIAL_COLOURS = ("#1c7ed6", "#e8590c", "#2f9e44", "#ae3ec9")
# A turtle's trail: turtlesim's own pen colour first, then colours that stand out on its blue
# (set_pen is a service call and the sim's trails topic is hidden: no bag holds the pens).
TURTLE_PENS = ("#b3b8ff", "#ffd43b", "#ff8787", "#8ce99a", "#ffffff", "#ffa94d")
TURTLE_BODY = (46, 139, 87)  # as the Turtlesim tool draws a turtle
TURTLE_EDGE = (20, 70, 40)
NOTHING = (
    "_Nothing to watch yet._ After **Check my node**, click **Watch this attempt** under "
    "the results: the grading plays here."
)


class TopView:
    """World metres -> pixels of the top view (y up, as a map is read)."""

    def __init__(
        self, low: tuple[float, float], high: tuple[float, float], scale: float | None = None
    ) -> None:
        span_x, span_y = max(high[0] - low[0], 0.5), max(high[1] - low[1], 0.5)
        self.scale = scale or min((WIDTH - 20) / span_x, (HEIGHT - 40) / span_y)
        self.low = low
        self.height = span_y * self.scale + 20
        self.width = span_x * self.scale + 20

    def px(self, x: float, y: float) -> tuple[float, float]:
        return 10 + (x - self.low[0]) * self.scale, self.height - 10 - (
            y - self.low[1]
        ) * self.scale

    @classmethod
    def around(cls, track: Track) -> TopView:
        """Turtlesim's window at its own size; else the floor, or everything the robot went
        past and saw."""
        if track.world == "turtlesim":
            return cls((0.0, 0.0), (WORLD_SIZE, WORLD_SIZE), scale=METER)
        if track.floor is not None:
            corners = [c for box in (track.floor, *track.room) for c in box.corners()]
        else:
            corners = [(p.x, p.y) for p in track.poses]
            corners += [c for box in track.room for c in box.corners()]
            corners += [
                pt for scan in track.scans[:: max(1, len(track.scans) // 50)] for pt in scan.points
            ]
        corners = corners or [(0.0, 0.0)]
        xs, ys = [c[0] for c in corners], [c[1] for c in corners]
        return cls(
            (min(xs) - MARGIN_M, min(ys) - MARGIN_M), (max(xs) + MARGIN_M, max(ys) + MARGIN_M)
        )


def _xy(x: float, y: float) -> str:
    return f"{x:.1f},{y:.1f}"


def _rgb(colour: tuple[int, int, int]) -> str:
    return "#{:02x}{:02x}{:02x}".format(*colour)


def _polygon(view: TopView, box: Box, style: str) -> str:
    points = " ".join(_xy(*view.px(x, y)) for x, y in box.corners())
    return f'<polygon points="{points}" {style}><title>{html.escape(box.name)}</title></polygon>'


def _way(view: TopView, piece: list[Pose], colour: str, width: float = 2) -> str:
    points: list[tuple[float, float]] = []
    for pose in piece:
        here = view.px(pose.x, pose.y)
        if not points or math.dist(here, points[-1]) >= WAY_STEP_PX or pose is piece[-1]:
            points.append(here)
    text = " ".join(f"{x:.1f},{y:.1f}" for x, y in points)
    return (
        f'<polyline points="{text}" fill="none" stroke="{colour}" stroke-width="{width:g}" '
        'stroke-linejoin="round" stroke-linecap="round"/>'
    )


def _pose_data(pose: Pose) -> str:
    """The pose drawn, as attributes: a test (or a curious learner's devtools) reads it."""
    return (
        f'data-x="{pose.x:.3f}" data-y="{pose.y:.3f}" data-yaw="{pose.yaw:.3f}" '
        f'data-t="{pose.t:.6f}"'  # to the microsecond: two poses can be 1 ms apart
    )


def _robot_world(track: Track, t: float, view: TopView) -> tuple[list[str], str]:
    """The room, the way so far (a line per trial), the scan and the robot at ``t``."""
    parts = []
    if track.floor is not None:
        parts.append(_polygon(view, track.floor, 'fill="#f8f9fa" stroke="#ced4da"'))
    parts += [_polygon(view, box, 'fill="#adb5bd" stroke="#495057"') for box in track.room]
    pieces = track.way_until(t)
    for n, piece in enumerate(pieces):
        parts.append(_way(view, piece, TRIAL_COLOURS[n % len(TRIAL_COLOURS)]))
    scan = track.scan_at(t)
    if scan is not None and t - scan.t < 1.0:
        dots = "".join(
            '<circle cx="{:.1f}" cy="{:.1f}" r="1.6"/>'.format(*view.px(x, y))
            for x, y in scan.points
        )
        parts.append(f'<g class="replay-scan" fill="#e03131">{dots}</g>')
    pose = track.pose_at(t)
    if pose is not None:
        cx, cy = view.px(pose.x, pose.y)
        r = ROBOT_RADIUS_M * view.scale
        nose = view.px(
            pose.x + ROBOT_RADIUS_M * math.cos(pose.yaw),
            pose.y + ROBOT_RADIUS_M * math.sin(pose.yaw),
        )
        parts.append(
            f'<g id="replay-robot" {_pose_data(pose)}>'
            f'<circle cx="{cx:.1f}" cy="{cy:.1f}" r="{r:.1f}" fill="#ffd43b" stroke="#212529" '
            f'stroke-width="1.5"/><line x1="{cx:.1f}" y1="{cy:.1f}" x2="{nose[0]:.1f}" '
            f'y2="{nose[1]:.1f}" stroke="#212529" stroke-width="2.5"/></g>'
        )
    trials = f" · trial {len(pieces)}" if len(pieces) > 1 else ""
    clock = track.trial_seconds(t)
    simulated = f" ({clock:.1f} s simulated into the trial)" if clock is not None else ""
    caption = (
        f"{t:.1f} s of {track.duration:.1f} s{simulated}{trials} · seen from above: the line "
        f"is where the robot really went ({track.pose_topic}), red dots what its /scan saw"
    )
    return parts, caption


def _turtle(view: TopView, name: str, pose: Pose, colour: str) -> str:
    """A turtle as turtlesim's window draws one (the Turtlesim tool's shape), named."""
    cx, cy = view.px(pose.x, pose.y)
    k = view.scale / METER  # the shape is in the window's pixels
    fx, fy = math.cos(pose.yaw) * k, -math.sin(pose.yaw) * k  # window y grows downwards
    sx, sy = -fy, fx
    shell = [(13, 0), (8, 11), (-10, 11), (-15, 0), (-10, -11), (8, -11)]
    points = " ".join(_xy(cx + a * fx + b * sx, cy + a * fy + b * sy) for a, b in shell)
    hx, hy = cx + 18 * fx, cy + 18 * fy
    return (
        f'<g class="replay-turtle" data-name="{html.escape(name)}" {_pose_data(pose)}>'
        f'<circle cx="{hx:.1f}" cy="{hy:.1f}" r="{5 * k:.1f}" fill="{_rgb(TURTLE_BODY)}" '
        f'stroke="{_rgb(TURTLE_EDGE)}"/><polygon points="{points}" fill="{_rgb(TURTLE_BODY)}" '
        f'stroke="{_rgb(TURTLE_EDGE)}" stroke-width="1.5"/>'
        f'<text x="{cx:.1f}" y="{cy - 20 * k:.1f}" text-anchor="middle" fill="{colour}" '
        'stroke="#1c2159" stroke-width="3" paint-order="stroke" '
        f'font-weight="bold">{html.escape(name)}</text></g>'
    )


def _turtlesim_world(track: Track, t: float, view: TopView) -> tuple[list[str], str]:
    """Turtlesim's window at ``t``: its blue ground, each turtle's trail so far and the turtles."""
    (x0, y1), (x1, y0) = view.px(0.0, 0.0), view.px(WORLD_SIZE, WORLD_SIZE)
    parts = [
        f'<rect x="{x0:.1f}" y="{y0:.1f}" width="{x1 - x0:.1f}" height="{y1 - y0:.1f}" '
        f'fill="{_rgb(DEFAULT_BACKGROUND)}"/>'
    ]
    colours = {name: TURTLE_PENS[n % len(TURTLE_PENS)] for n, name in enumerate(track.turtles)}
    for name in track.turtles:
        trail = track.trail_until(name, t)
        if len(trail) > 1:
            parts.append(_way(view, trail, colours[name], width=3 * view.scale / METER))
    now = track.turtles_at(t)
    parts += [_turtle(view, name, pose, colours[name]) for name, pose in now.items()]
    named = ", ".join(f"/{name}/pose" for name in track.turtles)
    caption = (
        f"{t:.1f} s of {track.duration:.1f} s · turtlesim's window: each turtle where its pose "
        f"put it ({named}), its trail so far in a colour of its own (pens are not recorded)"
    )
    return parts, caption


def top_view_svg(track: Track, t: float, view: TopView | None = None) -> str:
    """What moves, seen from above at ``t`` seconds into the bag: the simulated world's
    robot or turtlesim's window. The svg says its cursor (``data-cursor``)."""
    view = view or TopView.around(track)
    if track.world == "turtlesim":
        parts, caption = _turtlesim_world(track, t, view)
    else:
        parts, caption = _robot_world(track, t, view)
    lines = textwrap.wrap(caption, max(20, int((view.width - 20) / CAPTION_CHAR_PX)))
    height = view.height + 8 + CAPTION_LINE_PX * len(lines)
    text = "".join(
        f'<text x="10" y="{view.height + 2 + CAPTION_LINE_PX * (n + 1):.0f}" fill="#495057">'
        f"{html.escape(line)}</text>"
        for n, line in enumerate(lines)
    )
    return (
        f'<svg class="stage-replay" data-cursor="{t:.3f}" width="{view.width:.0f}" '
        f'height="{height:.0f}" viewBox="0 0 {view.width:.0f} {height:.0f}" '
        f'font-family="sans-serif" font-size="12" role="img" '
        f'aria-label="The recorded run seen from above at {t:.1f} s">'
        f"{''.join(parts)}{text}</svg>"
    )


def timeline_at(track: Track, t: float) -> str:
    """Each topic's messages as ticks, with a red cursor at ``t``."""
    start = track.info.start_ns
    stamps = {topic: [start + int(s * 1e9) for s in times] for topic, times in track.stamps.items()}
    return timeline_svg(BagPicture(track.info, stamps), cursor_ns=start + int(t * 1e9))


class ReplayStage:
    def __init__(self, gui: viser.GuiApi, ui: UiLoop) -> None:
        self._ui = ui
        self._active = False
        self._track: Track | None = None
        self._view: TopView | None = None
        self._t = 0.0
        self._playing = False
        self._last_frame = 0.0
        self._drawn = ""
        self._box = gui.add_folder("Watch a recording", expand_by_default=True, visible=False)
        with self._box:
            self._heading = MarkdownView(gui, NOTHING)
            self._play = gui.add_button("Play", icon=viser.Icon.PLAYER_PLAY, disabled=True)
            self._speed = gui.add_dropdown("Speed", list(SPEEDS), initial_value="1×")
            self._slider = gui.add_slider(
                "Time (s)", min=0.0, max=1.0, step=0.1, initial_value=0.0, disabled=True
            )
            self._picture = gui.add_html("")
            self._messages = MarkdownView(gui, "")
        self._play.on_click(ui.callback(self._toggle))
        self._slider.on_update(self._slider_moved)

    # -- opening ------------------------------------------------------------------

    def open(self, bag: Path, heading: str = "") -> None:
        """Read ``bag`` (a worker job) and show it from its start, paused."""
        self._playing = False
        self._track = None
        self._slider.disabled = self._play.disabled = True  # until it is read (if ever)
        self._heading.show(f"{heading}\n\n_Reading `{bag.name}`…_".strip())
        self._set_picture("")
        self._messages.show("")

        def done(track: Track) -> None:
            self._track, self._view = track, TopView.around(track) if track.drives else None
            self._slider.max = max(track.duration, 0.1)
            self._slider.disabled = self._play.disabled = False
            self._t = 0.0
            what = {
                "robot": "It plays from the start: **Pause** stops it, the time slider goes to "
                "any moment.",
                "turtlesim": "It plays from the start in turtlesim's window: **Pause** stops "
                "it, the time slider goes to any moment.",
            }.get(track.world, "No robot in this recording: its messages, topic by topic.")
            damaged = (
                f"\n\n⚠ Some messages could not be read: {'; '.join(track.problems)}"
                if track.problems
                else ""
            )
            self._heading.show(
                f"{heading}\n\n`{bag.name}` · {track.info.message_count} messages in "
                f"{track.duration:.1f} s. {what}{damaged}".strip()
            )
            self._playing = track.drives
            self._last_frame = time.monotonic()
            self._draw()

        def failed(text: str) -> None:
            self._heading.show(f"{heading}\n\n✗ This recording cannot be played: {text}".strip())

        self._ui.run_job(lambda: read_track(bag), done, failed)

    # -- UI thread ------------------------------------------------------------------

    def _toggle(self) -> None:
        if self._track is None:
            return
        if not self._playing and self._t >= self._track.duration:
            self._t = 0.0  # at the end: Play starts over
        self._playing = not self._playing
        self._last_frame = time.monotonic()
        self._draw()

    def _slider_moved(self, event: object) -> None:
        """viser's thread: a time the browser set (a drag, or a time typed in the box).

        The value travels with the intent: read later on the UI thread, the handle could
        already hold a playing frame's own time (each frame sets the slider), and the
        learner's time would be lost. The server's own settings (no client) are ignored.
        """
        if getattr(event, "client", True) is None:
            return
        value = float(self._slider.value)
        self._ui.post(lambda: self._go_to(value))

    def _go_to(self, t: float) -> None:
        if self._track is not None:
            self._t = min(max(t, 0.0), self._track.duration)
            self._last_frame = time.monotonic()  # playing goes on from there
            self._draw()

    def set_active(self, active: bool) -> None:
        self._active = active
        self._box.visible = active
        if not active:
            self._playing = False

    @property
    def playing(self) -> bool:
        """Whether a frame is due at each refresh (the teacher page refreshes faster then)."""
        return self._active and self._playing and self._track is not None

    def refresh(self, graph: GraphSnapshot | None = None) -> None:
        """One frame while playing (the graph is not used: the stage's parts all take it)."""
        track = self._track
        if not self._active or track is None or not self._playing:
            return
        now = time.monotonic()
        self._t = min(
            track.duration, self._t + (now - self._last_frame) * SPEEDS.get(self._speed.value, 1.0)
        )
        self._last_frame = now
        if self._t >= track.duration:
            self._playing = False
        self._draw()

    def _draw(self) -> None:
        track = self._track
        if track is None:
            return
        self._play.label = "Pause" if self._playing else "Play"
        self._play.icon = viser.Icon.PLAYER_PAUSE if self._playing else viser.Icon.PLAYER_PLAY
        assign(self._slider, round(self._t, 1))
        if track.drives:
            self._set_picture(top_view_svg(track, self._t, self._view))
        else:
            self._set_picture(timeline_at(track, self._t))
        lines = [
            f"{m.t:7.2f} s  {m.topic}  {m.text}"
            for m in track.moments_until(self._t, LINES_AT_CURSOR)
        ]
        self._messages.show(
            f"**The last messages up to {self._t:.1f} s** (what was sent, what came back)\n\n"
            + code_block(lines, "(none yet)")
        )

    def _set_picture(self, svg: str) -> None:
        if svg != self._drawn:
            self._drawn = svg
            self._picture.content = svg

    def close(self) -> None:
        self._playing = False
