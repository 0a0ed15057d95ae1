"""The turtlesim world: turtles, their motion and their pen trails, without ROS.

``nodes/turtlesim_node.py`` is only the ROS face of this module: it turns
topics, services and the action into calls here and publishes what ``step``
reports. Keeping the simulation free of rclpy makes it unit-testable and lets
a browser view draw the same state (``segments`` and ``turtles``).

Behaviour follows ROS 2 Jazzy's turtlesim (learned from its source, written
anew here):

- The window is 500 x 500 pixels at 45 pixels per metre, so the world is
  ``(500 - 1) / 45 = 11.088889`` m on each side; turtle1 starts at its centre.
- Every update advances each turtle by a *fixed* 16 ms, whatever the wall
  clock did: first queued teleports (in order), then a rotation goal, then the
  1 s command timeout, then the motion, then the wall clamp.
- Upstream keeps positions in the window's coordinates (y grows downwards);
  only the wall warning shows them, so ``WallHit`` carries those numbers.
- Pens draw 3-pixel lines into a transparent canvas; the colour sensor reads
  that canvas under the turtle. As upstream, unpainted ground reads
  (255, 255, 255), the canvas's transparent white, whatever the background.

Trails for viewers (the browser's Turtlesim tab) travel as packets of bytes
(``encode_segments``, ``encode_snapshot``, ``decode_trails``): a 20-byte
header (kind, the sim's session, its clear count, the index of the first
segment), then either 20 bytes per new segment (four float32 coordinates, r,
g, b, width) or the whole canvas and its painted mask, zlib-compressed. A
viewer applies segments whose index follows the last one it has, and asks for
a snapshot whenever it has not (opened late, missed a packet, the sim
restarted).
"""

from __future__ import annotations

import math
import struct
import zlib
from collections import deque
from dataclasses import dataclass, field
from enum import Enum

import numpy as np

PIXELS = 500  # the window's width and height
METER = 45.0  # pixels per metre (the height of upstream's turtle images)
# 11.088889 m; upstream keeps it in a float (32 bits), so do we, for the same logs.
WORLD_SIZE = float(np.float32((PIXELS - 1) / METER))
CENTRE = WORLD_SIZE / 2.0  # 5.544445 m
UPDATE_PERIOD = 0.016  # seconds of simulated time per update
COMMAND_TIMEOUT = 1.0  # seconds without cmd_vel before a turtle stops
ROTATE_SPEED = 1.0  # rad/s while a rotate_absolute goal runs
ROTATE_TOLERANCE = 0.02  # rad: a rotate_absolute goal is reached within this
DEFAULT_PEN = (179, 184, 255)  # 0xb3, 0xb8, 0xff
DEFAULT_PEN_WIDTH = 3  # pixels
UNPAINTED = (255, 255, 255)  # the transparent canvas's colour, read by the sensor
DEFAULT_BACKGROUND = (69, 86, 255)
TURTLE_IMAGES = 10  # upstream picks one of 10 distro turtles at random
MAX_SEGMENTS = 200_000  # trail segments kept for viewers; the canvas keeps all

RGB = tuple[int, int, int]


class BadRequest(ValueError):
    """A request the world refuses (a NaN or infinite number): the node logs it."""


def _require_finite(what: str, *values: float) -> None:
    # One NaN would poison a turtle for good (and the canvas maths); refuse it.
    if not all(math.isfinite(v) for v in values):
        raise BadRequest(f"{what}: every number must be finite, got {values}")


def normalize_angle(angle: float) -> float:
    """Into [-pi, pi), as upstream does after every step."""
    return angle - 2.0 * math.pi * math.floor((angle + math.pi) / (2.0 * math.pi))


class GoalOutcome(str, Enum):
    SUCCEEDED = "succeeded"
    CANCELED = "canceled"
    ABORTED = "aborted"


@dataclass(frozen=True)
class Segment:
    """One straight piece of pen trail, in metres (y up), with the pen that drew it."""

    x0: float
    y0: float
    x1: float
    y1: float
    color: RGB
    width: int


@dataclass(frozen=True)
class WallHit:
    """Where a turtle tried to go, in the window's coordinates (y down), as upstream logs."""

    x: float
    y: float

    def message(self) -> str:
        return f"Oh no! I hit the wall! (Clamping from [x={self.x:f}, y={self.y:f}])"


@dataclass(frozen=True)
class RotationUpdate:
    """What a rotate_absolute goal did in one step: feedback, and maybe its end."""

    goal_id: object
    remaining: float
    delta: float
    outcome: GoalOutcome | None = None


@dataclass(frozen=True)
class TurtleReport:
    """Everything the node publishes or logs for one turtle after one step."""

    name: str
    x: float
    y: float
    theta: float
    linear_velocity: float
    angular_velocity: float
    color: RGB
    wall_hit: WallHit | None = None
    rotation: RotationUpdate | None = None


@dataclass
class Rotation:
    """A running rotate_absolute goal; ``goal_id`` is whatever the node uses to find it."""

    goal_id: object
    target: float
    start_theta: float
    cancel_requested: bool = False
    delta: float = 0.0


@dataclass
class Turtle:
    """One turtle's state. Position in metres with y up; theta in [-pi, pi)."""

    name: str
    x: float
    y: float
    theta: float
    image: int = 0
    linear_x: float = 0.0
    linear_y: float = 0.0
    angular: float = 0.0
    last_command: float = 0.0  # the clock's seconds at the last cmd_vel (or rotation step)
    pen_on: bool = True
    pen_color: RGB = DEFAULT_PEN
    pen_width: int = DEFAULT_PEN_WIDTH
    teleports: list[tuple[bool, float, float, float]] = field(default_factory=list)
    rotation: Rotation | None = None


class TurtleWorld:
    """All turtles and the canvas. One owner thread; nothing here locks."""

    def __init__(self, seed: int | None = None) -> None:
        self.turtles: dict[str, Turtle] = {}
        self.canvas = np.zeros((PIXELS, PIXELS, 3), np.uint8)  # row = window y, col = x
        self.painted = np.zeros((PIXELS, PIXELS), bool)
        self.segments: deque[Segment] = deque(maxlen=MAX_SEGMENTS)
        self.segment_count = 0  # ever drawn: a viewer asks for those after its last count
        self.clear_count = 0  # a viewer that saw an older value redraws from scratch
        self._id_counter = 0
        self._random = np.random.default_rng(seed)
        self.clear()

    # -- the global services ---------------------------------------------------

    def spawn(self, name: str, x: float, y: float, theta: float, now: float = 0.0) -> str | None:
        """Add a turtle; an empty name gets the next free turtleN. None if the name is taken."""
        _require_finite("spawn", x, y, theta)
        if not name:
            while True:
                self._id_counter += 1
                name = f"turtle{self._id_counter}"
                if name not in self.turtles:
                    break
        elif name in self.turtles:
            return None
        image = int(self._random.integers(TURTLE_IMAGES))
        self.turtles[name] = Turtle(name, x, y, theta, image=image, last_command=now)
        return name

    def kill(self, name: str) -> Turtle | None:
        """Remove a turtle and return it (to end its rotation goal); None if there is none."""
        return self.turtles.pop(name, None)

    def clear(self) -> None:
        """Wipe every trail; turtles stay where they are."""
        self.canvas[:] = UNPAINTED
        self.painted[:] = False
        self.segments.clear()
        self.clear_count += 1

    def reset(self, now: float = 0.0) -> list[Rotation]:
        """Remove every turtle, spawn turtle1 at the centre, clear. Returns goals left running."""
        dropped = [t.rotation for t in self.turtles.values() if t.rotation is not None]
        self.turtles.clear()
        self._id_counter = 0
        self.spawn("", CENTRE, CENTRE, 0.0, now)
        self.clear()
        return dropped

    # -- per-turtle requests (queued or applied at the next step, as upstream) -

    def command_velocity(
        self, name: str, linear_x: float, linear_y: float, angular: float, now: float,
        holonomic: bool = False,
    ) -> Rotation | None:  # fmt: skip
        """A cmd_vel: returns the rotation goal it aborts, if one was running."""
        _require_finite("cmd_vel", linear_x, linear_y, angular)
        turtle = self.turtles[name]
        turtle.last_command = now
        turtle.linear_x = linear_x
        if holonomic:
            turtle.linear_y = linear_y
        turtle.angular = angular
        aborted, turtle.rotation = turtle.rotation, None
        return aborted

    def set_pen(self, name: str, r: int, g: int, b: int, width: int, off: int) -> None:
        turtle = self.turtles[name]
        turtle.pen_on = not off
        if off:
            return  # the colour and width stay as they were
        turtle.pen_color = (r, g, b)
        turtle.pen_width = width if width != 0 else 1  # a new Qt pen is 1 pixel wide

    def teleport_absolute(self, name: str, x: float, y: float, theta: float) -> None:
        _require_finite("teleport_absolute", x, y, theta)
        self.turtles[name].teleports.append((False, x, y, theta))

    def teleport_relative(self, name: str, linear: float, angular: float) -> None:
        _require_finite("teleport_relative", linear, angular)
        self.turtles[name].teleports.append((True, linear, 0.0, angular))

    def start_rotation(self, name: str, goal_id: object, theta: float) -> Rotation | None:
        """A new rotate_absolute goal; returns the goal it replaces (to abort), if any."""
        _require_finite("rotate_absolute", theta)
        turtle = self.turtles[name]
        previous = turtle.rotation
        turtle.rotation = Rotation(goal_id, theta, turtle.theta)
        return previous

    def cancel_rotation(self, name: str, goal_id: object) -> None:
        """Honoured at the next step (the goal then ends as canceled)."""
        turtle = self.turtles.get(name)
        if turtle and turtle.rotation and turtle.rotation.goal_id == goal_id:
            turtle.rotation.cancel_requested = True

    # -- the 16 ms update --------------------------------------------------------

    def step(self, now: float, dt: float = UPDATE_PERIOD) -> list[TurtleReport]:
        """Advance every turtle (in name order, as upstream's std::map) by ``dt``."""
        return [self._step_turtle(self.turtles[name], now, dt) for name in sorted(self.turtles)]

    def _step_turtle(self, turtle: Turtle, now: float, dt: float) -> TurtleReport:
        for relative, a, b, theta in turtle.teleports:
            old = (turtle.x, turtle.y)
            if relative:
                turtle.theta += theta
                turtle.x += math.cos(turtle.theta) * a
                turtle.y += math.sin(turtle.theta) * a
            else:
                turtle.x = a
                turtle.y = min(WORLD_SIZE, b)  # upstream clamps window y at 0 here
                turtle.theta = theta
            self._draw(turtle, old)
        turtle.teleports.clear()

        rotation = self._step_rotation(turtle, now)

        if now - turtle.last_command > COMMAND_TIMEOUT:
            turtle.linear_x = turtle.linear_y = turtle.angular = 0.0

        old = (turtle.x, turtle.y)
        turtle.theta = normalize_angle(turtle.theta + turtle.angular * dt)
        cos, sin = math.cos(turtle.theta), math.sin(turtle.theta)
        turtle.x += (cos * turtle.linear_x - sin * turtle.linear_y) * dt
        turtle.y += (sin * turtle.linear_x + cos * turtle.linear_y) * dt

        hit = None
        if not (0.0 <= turtle.x <= WORLD_SIZE and 0.0 <= turtle.y <= WORLD_SIZE):
            hit = WallHit(turtle.x, WORLD_SIZE - turtle.y)
            turtle.x = min(max(turtle.x, 0.0), WORLD_SIZE)
            turtle.y = min(max(turtle.y, 0.0), WORLD_SIZE)
        if (turtle.x, turtle.y) != old:
            self._draw(turtle, old)

        return TurtleReport(
            name=turtle.name,
            x=turtle.x,
            y=turtle.y,
            theta=turtle.theta,
            linear_velocity=math.hypot(turtle.linear_x, turtle.linear_y),
            angular_velocity=turtle.angular,
            color=self.color_under(turtle.x, turtle.y),
            wall_hit=hit,
            rotation=rotation,
        )

    def _step_rotation(self, turtle: Turtle, now: float) -> RotationUpdate | None:
        goal = turtle.rotation
        if goal is None:
            return None
        if goal.cancel_requested:
            turtle.rotation = None
            turtle.linear_x = turtle.linear_y = turtle.angular = 0.0
            return RotationUpdate(goal.goal_id, 0.0, goal.delta, GoalOutcome.CANCELED)
        target = normalize_angle(goal.target)
        remaining = normalize_angle(target - turtle.theta)
        goal.delta = normalize_angle(goal.start_theta - turtle.theta)
        if abs(normalize_angle(turtle.theta - target)) < ROTATE_TOLERANCE:
            turtle.rotation = None
            turtle.linear_x = turtle.linear_y = turtle.angular = 0.0
            return RotationUpdate(goal.goal_id, remaining, goal.delta, GoalOutcome.SUCCEEDED)
        turtle.linear_x = turtle.linear_y = 0.0
        turtle.angular = -ROTATE_SPEED if remaining < 0.0 else ROTATE_SPEED
        turtle.last_command = now  # a running goal keeps the turtle from timing out
        return RotationUpdate(goal.goal_id, remaining, goal.delta)

    # -- the canvas ----------------------------------------------------------------

    def color_under(self, x: float, y: float) -> RGB:
        col, row = _pixel(x, y)
        r, g, b = (int(v) for v in self.canvas[row, col])
        return (r, g, b)

    def _draw(self, turtle: Turtle, old: tuple[float, float]) -> None:
        if not turtle.pen_on:
            return
        segment = Segment(old[0], old[1], turtle.x, turtle.y, turtle.pen_color, turtle.pen_width)
        self.segments.append(segment)
        self.segment_count += 1
        self._paint(segment)

    def _paint(self, seg: Segment) -> None:
        paint_segment(self.canvas, self.painted, seg)

    def segments_since(self, count: int) -> list[Segment]:
        """Trail pieces drawn after a viewer's last ``segment_count`` (all it still has)."""
        new = self.segment_count - count
        if new <= 0:
            return []
        kept = self.segments
        if new >= len(kept):
            return list(kept)
        # Index from the right end: cheap on a deque, where a full copy of 200k is not.
        return [kept[i] for i in range(-new, 0)]


def _pixel(x: float, y: float) -> tuple[int, int]:
    """The window pixel (column, row) under a point, rounded as Qt's toPoint() does."""
    col = int(math.floor(x * METER + 0.5))
    row = int(math.floor((WORLD_SIZE - y) * METER + 0.5))
    return min(max(col, 0), PIXELS - 1), min(max(row, 0), PIXELS - 1)


def paint_segment(canvas: np.ndarray, painted: np.ndarray, seg: Segment) -> None:
    """Fill the pixels within half the pen width of the segment (in window pixels)."""
    ax, ay = seg.x0 * METER, (WORLD_SIZE - seg.y0) * METER
    bx, by = seg.x1 * METER, (WORLD_SIZE - seg.y1) * METER
    # Round to the pixel grid as the sensor does, so a 1-pixel pen still covers it.
    reach = max(seg.width / 2.0, 0.75)
    lo_c = max(int(math.floor(min(ax, bx) - reach)), 0)
    hi_c = min(int(math.ceil(max(ax, bx) + reach)), PIXELS - 1)
    lo_r = max(int(math.floor(min(ay, by) - reach)), 0)
    hi_r = min(int(math.ceil(max(ay, by) + reach)), PIXELS - 1)
    if lo_c > hi_c or lo_r > hi_r:
        return
    cols = np.arange(lo_c, hi_c + 1, dtype=float)[None, :]
    rows = np.arange(lo_r, hi_r + 1, dtype=float)[:, None]
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0 else np.clip(((cols - ax) * dx + (rows - ay) * dy) / length2, 0, 1)
    dist2 = (cols - (ax + t * dx)) ** 2 + (rows - (ay + t * dy)) ** 2
    mask = dist2 <= reach * reach
    canvas[lo_r : hi_r + 1, lo_c : hi_c + 1][mask] = seg.color
    painted[lo_r : hi_r + 1, lo_c : hi_c + 1] |= mask


# -- trails for viewers ---------------------------------------------------------------

TRAILS_VERSION = 1
SEGMENTS, SNAPSHOT = 0, 1  # packet kinds
# version, kind, (2 spare), session, clear count, index of the first segment
_HEADER = struct.Struct("<BBxxIIQ")
_SEGMENT = np.dtype(
    [("x0", "<f4"), ("y0", "<f4"), ("x1", "<f4"), ("y1", "<f4"), ("rgbw", "u1", (4,))]
)


@dataclass(frozen=True)
class TrailsPacket:
    """One decoded packet: new segments from ``start`` on, or the whole canvas at ``start``."""

    kind: int
    session: int
    clear_count: int
    start: int
    segments: tuple[Segment, ...] = ()
    canvas: np.ndarray | None = None  # (PIXELS, PIXELS, 3) uint8, for a snapshot
    painted: np.ndarray | None = None  # (PIXELS, PIXELS) bool, for a snapshot


def encode_segments(session: int, clear_count: int, start: int, segments: list[Segment]) -> bytes:
    records = np.zeros(len(segments), _SEGMENT)
    for i, seg in enumerate(segments):
        records[i] = (seg.x0, seg.y0, seg.x1, seg.y1, (*seg.color, min(seg.width, 255)))
    return _HEADER.pack(TRAILS_VERSION, SEGMENTS, session, clear_count, start) + records.tobytes()


def encode_snapshot(session: int, world: TurtleWorld) -> bytes:
    """The whole picture (a few kB once compressed): what a late viewer starts from."""
    header = _HEADER.pack(TRAILS_VERSION, SNAPSHOT, session, world.clear_count, world.segment_count)
    body = world.canvas.tobytes() + np.packbits(world.painted).tobytes()
    return header + zlib.compress(body, 1)


def decode_trails(data: bytes) -> TrailsPacket:
    """A packet from ``encode_*``; ValueError if it is not one."""
    if len(data) < _HEADER.size:
        raise ValueError("trails packet too short")
    version, kind, session, clear_count, start = _HEADER.unpack_from(data)
    if version != TRAILS_VERSION or kind not in (SEGMENTS, SNAPSHOT):
        raise ValueError(f"unknown trails packet (version {version}, kind {kind})")
    body = data[_HEADER.size :]
    if kind == SEGMENTS:
        if len(body) % _SEGMENT.itemsize:
            raise ValueError("trails packet cut in the middle of a segment")
        records = np.frombuffer(body, _SEGMENT)
        segments = tuple(
            Segment(
                float(x0),
                float(y0),
                float(x1),
                float(y1),
                (int(c[0]), int(c[1]), int(c[2])),
                int(c[3]),
            )
            for x0, y0, x1, y1, c in records
        )
        return TrailsPacket(kind, session, clear_count, start, segments)
    raw = zlib.decompress(body)
    size = PIXELS * PIXELS
    if len(raw) != size * 3 + size // 8:
        raise ValueError("trails snapshot of the wrong size")
    canvas = np.frombuffer(raw[: size * 3], np.uint8).reshape(PIXELS, PIXELS, 3).copy()
    painted = np.unpackbits(np.frombuffer(raw[size * 3 :], np.uint8)).astype(bool)
    return TrailsPacket(
        kind, session, clear_count, start, canvas=canvas, painted=painted.reshape(PIXELS, PIXELS)
    )
