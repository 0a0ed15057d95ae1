"""Turtlesim's window, drawn in the browser: background, pen trails and every turtle.

The picture is put together from what any ROS program could see:

- the pen trails from the sim's hidden ``~/_trails`` topic (packets decoded by
  ``nodes.common.turtlesim_world``): new segments are painted onto a canvas
  kept here, with the sim's own painting function, so the view matches the
  sim pixel for pixel; when a packet does not follow the last one (opened
  late, a lost packet, a restarted sim) the view asks for a snapshot;
- the background from the parameters ``background_r/g/b``;
- the turtles from their ``pose`` topics.

Threads: ROS callbacks (executor thread) and the panel (UI thread) only hand
data in under a lock and wake the drawing thread. That thread owns the
canvas: it applies packets, draws at most ``MAX_HZ`` times a second and only
when something changed, and sends the frame as a PNG (about 2 ms and 5 kB
for 500 x 500, measured).
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import cv2
import numpy as np
import viser

from nodes.common.turtlesim_world import (
    DEFAULT_BACKGROUND,
    METER,
    PIXELS,
    SNAPSHOT,
    WORLD_SIZE,
    TrailsPacket,
    decode_trails,
    paint_segment,
)

log = logging.getLogger(__name__)

MAX_HZ = 25.0  # the sim updates at 62.5 Hz; a browser panel is smooth at 25
SNAPSHOT_RETRY_SEC = 1.0  # while out of step, ask the sim again this often
TURTLE_BODY = (46, 139, 87)  # sea green, with a darker shell line
TURTLE_EDGE = (20, 70, 40)
LABEL = (255, 255, 255)
MARK = (255, 140, 0)  # another TF frame in world (tf2 lesson's carrot): orange
RGB = tuple[int, int, int]
WINDOW_TITLE = "TurtleSim"  # upstream's window title


@dataclass(frozen=True)
class ViewStats:
    frames: int  # frames sent to the browser since the view was made
    rate_hz: float | None  # over the last few seconds
    draw_ms: float | None  # mean cost of one frame (compose + encode), recent frames
    in_step: bool  # the trails follow the sim's packets (no snapshot pending)


def to_pixel(x: float, y: float) -> tuple[float, float]:
    """World metres (y up) to window pixels (y down), as the sim paints."""
    return x * METER, (WORLD_SIZE - y) * METER


def turtle_outline(x: float, y: float, theta: float) -> tuple[np.ndarray, np.ndarray]:
    """A turtle's shell (polygon) and head (centre), in pixels, pointing along ``theta``."""
    cx, cy = to_pixel(x, y)
    forward = np.array([math.cos(theta), -math.sin(theta)])  # window y grows downwards
    side = np.array([-forward[1], forward[0]])
    shell = [13 * forward, 8 * forward + 11 * side, -10 * forward + 11 * side, -15 * forward]
    shell += [-10 * forward - 11 * side, 8 * forward - 11 * side]
    points = np.array(shell) + (cx, cy)
    head = np.array((cx, cy)) + 18 * forward
    return np.round(points).astype(np.int32), head


class TurtlesimView:
    """Owns the panel image; fed from any thread, drawn by its own thread."""

    def __init__(
        self,
        gui: viser.GuiApi,
        request_snapshot: Callable[[], None],
        show: Callable[[np.ndarray], None] | None = None,
    ) -> None:
        """``show(frame)``: where a drawn frame goes (the drawing thread calls it); by
        default an image of its own in ``gui``."""
        self._request_snapshot = request_snapshot
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._stop = threading.Event()
        # Handed in under the lock; read by the drawing thread.
        self._packets: deque[bytes] = deque(maxlen=2000)
        self._poses: dict[str, tuple[float, float, float]] = {}
        self._marks: dict[str, tuple[float, float]] = {}  # other TF frames in world: (x, y)
        self._background: RGB = DEFAULT_BACKGROUND
        self._dirty = True
        self._restart = False
        self._active = False
        # Owned by the drawing thread: the ground (background and trails, what lies under
        # the turtles), the mask of what pens painted, and the background it was made with.
        self._ground = np.empty((PIXELS, PIXELS, 3), np.uint8)
        self._ground[:] = DEFAULT_BACKGROUND
        self._painted = np.zeros((PIXELS, PIXELS), bool)
        self._ground_background: RGB = DEFAULT_BACKGROUND
        self._position: tuple[int, int, int] | None = None  # (session, clears, next index)
        self._last_request = -math.inf
        # Statistics, under the lock.
        self._frames = 0
        self._in_step = False
        self._frame_times: deque[float] = deque(maxlen=90)
        self._draw_costs: deque[float] = deque(maxlen=30)
        if show is None:
            handle = gui.add_image(self._compose(), label=WINDOW_TITLE, format="png")
            show = partial(setattr, handle, "image")
        else:
            show(self._compose())
        self._show = show
        self._thread = threading.Thread(target=self._run, name="turtlesim-view", daemon=True)
        self._thread.start()

    # -- any thread --------------------------------------------------------------

    def offer_trails(self, data: bytes) -> None:
        with self._lock:
            self._packets.append(data)
        self._wake.set()

    def offer_pose(self, name: str, x: float, y: float, theta: float) -> None:
        with self._lock:
            if self._poses.get(name) == (x, y, theta):
                return  # a turtle at rest costs no frame
            self._poses[name] = (x, y, theta)
            self._dirty = True
        self._wake.set()

    def keep_turtles(self, names: set[str]) -> None:
        """Forget turtles whose pose topic has gone (killed, or the sim stopped)."""
        with self._lock:
            gone = set(self._poses) - names
            for name in gone:
                del self._poses[name]
            self._dirty = self._dirty or bool(gone)
        self._wake.set()

    def set_marks(self, marks: dict[str, tuple[float, float]]) -> None:
        """TF frames other than the turtles' (a carrot), where they are in ``world``."""
        rounded = {name: (round(x, 3), round(y, 3)) for name, (x, y) in marks.items()}
        with self._lock:
            if rounded == self._marks:
                return
            self._marks = rounded
            self._dirty = True
        self._wake.set()

    def set_background(self, rgb: RGB) -> None:
        with self._lock:
            if rgb != self._background:
                self._background = rgb
                self._dirty = True
        self._wake.set()

    @property
    def background(self) -> RGB:
        with self._lock:
            return self._background

    def follow(self, active: bool) -> None:
        """Start over for a new sim (or none): empty trails, no turtles, default background."""
        with self._lock:
            self._packets.clear()
            self._poses.clear()
            self._marks = {}
            self._background = DEFAULT_BACKGROUND
            self._restart = True
            self._active = active
            self._dirty = True
        self._wake.set()

    def redraw(self) -> None:
        """Draw the frame again (it is shown somewhere else now)."""
        with self._lock:
            self._dirty = True
        self._wake.set()

    def stats(self) -> ViewStats:
        now = time.monotonic()
        with self._lock:
            times = [t for t in self._frame_times if now - t < 3.0]
            costs = list(self._draw_costs)
            frames, in_step = self._frames, self._in_step
        rate = (len(times) - 1) / (times[-1] - times[0]) if len(times) >= 3 else None
        cost = 1000.0 * sum(costs) / len(costs) if costs else None
        return ViewStats(frames, rate, cost, in_step)

    def close(self) -> None:
        self._stop.set()
        self._wake.set()
        self._thread.join(timeout=2.0)

    # -- the drawing thread ------------------------------------------------------

    def _run(self) -> None:
        last_frame = 0.0
        while not self._stop.is_set():
            # Everything that gives work sets the wake, and so does stop(): no timeout
            # (a dozen such threads waking twice a second cost each dashboard of a class of 20
            # about 0.4 % of a core: bench/results/findings.md).
            self._wake.wait()
            self._wake.clear()
            wait = last_frame + 1.0 / MAX_HZ - time.monotonic()
            if wait > 0 and self._stop.wait(wait):
                break
            try:
                changed = self._take_packets()
                with self._lock:
                    changed, self._dirty = changed or self._dirty, False
                if changed:
                    started = time.monotonic()
                    self._show(self._compose())
                    last_frame = time.monotonic()
                    with self._lock:
                        self._frames += 1
                        self._frame_times.append(last_frame)
                        self._draw_costs.append(last_frame - started)
            except Exception:  # a bad packet or a closed page must not stop the view
                log.exception("drawing turtlesim failed")

    def _take_packets(self) -> bool:
        with self._lock:
            packets = list(self._packets)
            self._packets.clear()
            restart, self._restart = self._restart, False
            active = self._active
        changed = restart
        if restart:
            self._painted[:] = False
            self._ground[:] = self._ground_background
            self._position = None
        for data in packets:
            try:
                changed = self._apply(decode_trails(data)) or changed
            except ValueError as exc:
                log.warning("ignoring a trails packet: %s", exc)
        if active and self._position is None:
            now = time.monotonic()
            if now - self._last_request >= SNAPSHOT_RETRY_SEC:
                self._last_request = now
                self._request_snapshot()
            self._wake.set()  # come back to ask again
        with self._lock:
            self._in_step = self._position is not None
        return changed

    def _apply(self, packet: TrailsPacket) -> bool:
        """Paint one packet; False if it was skipped (out of step: a snapshot is asked for)."""
        if packet.kind == SNAPSHOT:
            assert packet.canvas is not None and packet.painted is not None
            self._painted[:] = packet.painted
            self._ground[:] = self._ground_background
            self._ground[self._painted] = packet.canvas[self._painted]
            self._position = (packet.session, packet.clear_count, packet.start)
            return True
        expected = self._position
        if expected is None or expected != (packet.session, packet.clear_count, packet.start):
            if expected is not None and expected[:2] == (packet.session, packet.clear_count):
                if packet.start + len(packet.segments) <= expected[2]:
                    return False  # already in the snapshot we have
            self._position = None  # out of step: ask for the whole picture
            return False
        for segment in packet.segments:
            paint_segment(self._ground, self._painted, segment)
        self._position = (packet.session, packet.clear_count, packet.start + len(packet.segments))
        return bool(packet.segments)

    def _compose(self) -> np.ndarray:
        with self._lock:
            background = self._background
            poses = sorted(self._poses.items())
            marks = sorted(self._marks.items())
        if background != self._ground_background:  # repaint only what no pen covered
            self._ground[~self._painted] = background
            self._ground_background = background
        frame = self._ground.copy()
        for name, (x, y) in marks:  # under the turtles: a carrot on a turtle hides under it
            mx, my = (int(round(v)) for v in to_pixel(x, y))
            cv2.circle(frame, (mx, my), 5, MARK, -1, cv2.LINE_AA)
            cv2.circle(frame, (mx, my), 5, (0, 0, 0), 1, cv2.LINE_AA)
            _label(
                frame, name, (min(max(mx + 8, 2), PIXELS - 60), min(max(my + 4, 12), PIXELS - 4))
            )
        for name, (x, y, theta) in poses:
            shell, head = turtle_outline(x, y, theta)
            hx, hy = (int(round(v)) for v in head)
            cv2.circle(frame, (hx, hy), 5, TURTLE_BODY, -1, cv2.LINE_AA)
            cv2.circle(frame, (hx, hy), 5, TURTLE_EDGE, 1, cv2.LINE_AA)
            cv2.fillPoly(frame, [shell], TURTLE_BODY, cv2.LINE_AA)
            cv2.polylines(frame, [shell], True, TURTLE_EDGE, 2, cv2.LINE_AA)
            cx, cy = (int(round(v)) for v in to_pixel(x, y))
            (width, _height), _base = cv2.getTextSize(name, cv2.FONT_HERSHEY_SIMPLEX, 0.45, 1)
            _label(
                frame, name, (min(max(cx - width // 2, 2), PIXELS - width - 2), max(cy - 20, 12))
            )
        return frame


def _label(frame: np.ndarray, text: str, origin: tuple[int, int]) -> None:
    """White words with a black edge: readable on any background and trail."""
    cv2.putText(frame, text, origin, cv2.FONT_HERSHEY_SIMPLEX, 0.45, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(frame, text, origin, cv2.FONT_HERSHEY_SIMPLEX, 0.45, LABEL, 1, cv2.LINE_AA)


class SideBySide:
    """One image holding two turtlesim windows side by side (``multisim``'s two sims):
    two stacked 500 px windows would not fit a laptop's screen. ``left``/``right`` are
    ``show`` callbacks for two views; called from their drawing threads."""

    GAP_PX = 12

    def __init__(self, gui: viser.GuiApi, label: str = WINDOW_TITLE) -> None:
        self._lock = threading.Lock()
        blank = np.full((PIXELS, PIXELS, 3), 255, np.uint8)
        self._frames = [blank, blank]
        self.handle = gui.add_image(self._joined(), label=label, format="png")

    def left(self, frame: np.ndarray) -> None:
        self._put(0, frame)

    def right(self, frame: np.ndarray) -> None:
        self._put(1, frame)

    def _put(self, side: int, frame: np.ndarray) -> None:
        with self._lock:  # in order: an older picture never replaces a newer one
            self._frames[side] = frame
            self.handle.image = self._joined()

    def _joined(self) -> np.ndarray:
        gap = np.full((PIXELS, self.GAP_PX, 3), 255, np.uint8)
        return np.hstack([self._frames[0], gap, self._frames[1]])
