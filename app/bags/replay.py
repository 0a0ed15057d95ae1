"""What a recording shows when it is watched: the robot's way, its scans, the room, the
turtles of turtlesim, and each topic's messages over time.

A graded attempt (app/exercises/attempts.py) or any bag of the simulated world
holds ``/ground_truth/odom`` (where the robot really was), ``/scan`` and the
world's latched ``/sim_world/static_markers`` (floor, walls, furniture). A
turtlesim exercise's attempt holds each turtle's ``/<turtle>/pose``
(``turtlesim/msg/Pose``). This reads them once into plain numbers a player can
step through by time: poses and scans as seen from above, the room as boxes,
each turtle's poses, and every other message as a line of text at its moment
(what the grader sent, what the node answered). Times are seconds since the
bag's first message, by when each was recorded.
"""

from __future__ import annotations

import bisect
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, TypeVar, cast

from rclpy.serialization import deserialize_message
from rosbags.rosbag2 import Reader

from app.bags.bagfile import READ_ERRORS, first_line, open_bag
from app.bags.errors import BagError
from app.bags.info import BagInfo, read_info
from app.ros import rotations
from app.ros.convert import import_type, to_plain
from app.ros.planar import Box, Pose

if TYPE_CHECKING:
    from geometry_msgs.msg import Quaternion
    from nav_msgs.msg import Odometry
    from rcl_interfaces.msg import Log
    from sensor_msgs.msg import LaserScan
    from turtlesim.msg import Pose as TurtlePose
    from visualization_msgs.msg import MarkerArray

POSE_TOPICS = ("/ground_truth/odom", "/odom")  # the first one a bag holds is the robot's way
SCAN_TOPIC = "/scan"
ROOM_TOPIC = "/sim_world/static_markers"
TURTLE_POSE = "turtlesim/msg/Pose"  # on /<turtle>/pose: a turtle of turtlesim
MOST_MOMENTS = 3000  # lines of other messages kept (a long bag keeps its first ones)
MOMENT_TEXT = 160  # characters of one message's text
FLOOR_HEIGHT = 0.05  # m: a marker no taller than this is floor, not an obstacle
LOG_LEVELS = {10: "DEBUG", 20: "INFO", 30: "WARN", 40: "ERROR", 50: "FATAL"}
SHORTEST_TRIAL = 0.5  # s: a shorter piece of the way is no trial (see Track.way_until)
JUMP = 0.5  # m between two poses: the world was reset (a new trial), not a drive
# Drawn, not listed: their numbers are the picture (and images and clouds are never kept).
DRAWN_TYPES = (
    "nav_msgs/msg/Odometry",
    "sensor_msgs/msg/LaserScan",
    "visualization_msgs/msg/MarkerArray",
    "tf2_msgs/msg/TFMessage",
    "rosgraph_msgs/msg/Clock",
    "sensor_msgs/msg/Imu",
    "sensor_msgs/msg/JointState",
    TURTLE_POSE,
)


@dataclass(frozen=True)
class Scan:
    """One scan's returns in the world frame, from where the robot was when it was taken."""

    t: float
    points: tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class Moment:
    """One message of a topic that is not drawn, as a line of text."""

    t: float
    topic: str
    text: str


@dataclass
class Track:
    """A bag made ready to watch."""

    info: BagInfo
    duration: float
    pose_topic: str = ""
    poses: list[Pose] = field(default_factory=list)
    sim_stamps: list[float] = field(default_factory=list)  # each pose's header stamp, in s
    scans: list[Scan] = field(default_factory=list)
    room: list[Box] = field(default_factory=list)
    floor: Box | None = None
    turtles: dict[str, list[Pose]] = field(default_factory=dict)  # by name, e.g. "turtle1"
    moments: list[Moment] = field(default_factory=list)
    stamps: dict[str, list[float]] = field(default_factory=dict)  # topic -> message times
    problems: list[str] = field(default_factory=list)  # messages that could not be read

    @property
    def world(self) -> str:
        """What plays seen from above: "robot" (the simulated world), "turtlesim" (its
        window), or "" (nothing moves: the messages' timeline). A robot wins over turtles."""
        if self.poses:
            return "robot"
        return "turtlesim" if self.turtles else ""

    @property
    def drives(self) -> bool:
        """Whether something moves to watch from above (else: the messages' timeline)."""
        return bool(self.world)

    def turtles_at(self, t: float) -> dict[str, Pose]:
        """Each turtle's newest pose at ``t``, by name (a turtle not spawned yet is left out)."""
        now = {name: _newest(poses, t) for name, poses in self.turtles.items()}
        return {name: pose for name, pose in now.items() if pose is not None}

    def trail_until(self, name: str, t: float) -> list[Pose]:
        """Turtle ``name``'s poses up to ``t``: its trail, as turtlesim's pen draws it (a
        teleport included: the pen draws that line too)."""
        poses = self.turtles.get(name, [])
        return poses[: bisect.bisect_right([p.t for p in poses], t)]

    def pose_at(self, t: float) -> Pose | None:
        """The newest pose at ``t`` (None before the first)."""
        return _newest(self.poses, t)

    def scan_at(self, t: float) -> Scan | None:
        return _newest(self.scans, t)

    def way_until(self, t: float) -> list[list[Pose]]:
        """The robot's way up to ``t``, cut where the world was reset: one piece per trial.

        A piece shorter than ``SHORTEST_TRIAL`` is the world standing where it started
        before the grader's first reset, not a trial: it is left out.
        """
        return [piece for piece, _ in self._pieces(t) if piece[-1].t - piece[0].t >= SHORTEST_TRIAL]

    def trial_seconds(self, t: float) -> float | None:
        """Simulated seconds since the current trial began, by the poses' own stamps (the
        grader runs the world faster than real time: its verdicts count in these)."""
        pieces = self._pieces(t)
        if not pieces:
            return None
        first, last = pieces[-1][1][0], pieces[-1][1][-1]
        return self.sim_stamps[last] - self.sim_stamps[first]

    def _pieces(self, t: float) -> list[tuple[list[Pose], list[int]]]:
        """The poses up to ``t`` cut at each jump, with their indices."""
        pieces: list[tuple[list[Pose], list[int]]] = []
        end = bisect.bisect_right([p.t for p in self.poses], t)
        for index, pose in enumerate(self.poses[:end]):
            last = pieces[-1][0][-1] if pieces else None
            if last is None or math.hypot(pose.x - last.x, pose.y - last.y) > JUMP:
                pieces.append(([], []))
            pieces[-1][0].append(pose)
            pieces[-1][1].append(index)
        return pieces

    def moments_until(self, t: float, most: int) -> list[Moment]:
        """The last ``most`` messages at or before ``t``."""
        end = bisect.bisect_right([m.t for m in self.moments], t)
        return self.moments[max(0, end - most) : end]


class _Timed(Protocol):
    @property
    def t(self) -> float: ...


Timed = TypeVar("Timed", bound=_Timed)


def _newest(items: Sequence[Timed], t: float) -> Timed | None:
    index = bisect.bisect_right([item.t for item in items], t) - 1
    return items[index] if index >= 0 else None


def yaw_of(q: Quaternion) -> float:
    return rotations.yaw_of(q.x, q.y, q.z, q.w)


def read_track(path: Path) -> Track:
    """The bag at ``path`` made ready to watch; BagError when it cannot be read at all.

    A message that cannot be decoded is counted in ``problems`` and skipped.
    """
    info = read_info(path)
    start = info.start_ns
    types = {t.name: t.msgtype for t in info.topics}
    pose_topic = next((t for t in POSE_TOPICS if t in types), "")
    track = Track(info, max(info.duration_ns, 0) / 1e9, pose_topic)
    classes: dict[str, type] = {}
    try:
        with open_bag(path) as reader:
            wanted = _wanted_messages(reader, track, start)
    except READ_ERRORS as exc:
        raise BagError(f"{path}: {first_line(exc)}") from None
    # A bag's file keeps messages in the order they were written, not always in time order
    # (the recorder writes a batch of one topic, then another's): sorted here, by receive time.
    for stamps in track.stamps.values():
        stamps.sort()
    for t, topic, kind, raw in sorted(wanted, key=lambda item: item[0]):
        if kind not in DRAWN_TYPES and len(track.moments) >= MOST_MOMENTS:
            continue
        try:
            cls = classes.get(kind) or classes.setdefault(kind, import_type(kind))
            msg = deserialize_message(raw, cls)
        except Exception as exc:  # a type we lack, or a damaged message
            if len(track.problems) < 5:
                track.problems.append(f"{topic}: {first_line(exc)}")
            continue
        _take(track, topic, kind, t, msg)
    return track


def _wanted_messages(
    reader: Reader, track: Track, start: int
) -> list[tuple[float, str, str, bytes]]:
    """Every message's time noted; the ones to draw or list kept as (t, topic, type, CDR)."""
    kept = []
    for connection, stamp, raw in reader.messages():
        topic, kind = connection.topic, connection.msgtype
        t = max(0.0, (stamp - start) / 1e9)
        track.stamps.setdefault(topic, []).append(t)
        drawn = topic in (track.pose_topic, SCAN_TOPIC, ROOM_TOPIC) or kind == TURTLE_POSE
        if drawn or kind not in DRAWN_TYPES:
            kept.append((t, topic, kind, bytes(raw)))
    return kept


def _take(track: Track, topic: str, kind: str, t: float, msg: object) -> None:
    """One message of the bag, of the type ``kind`` names."""
    if topic == track.pose_topic:
        odometry = cast("Odometry", msg)
        p = odometry.pose.pose
        track.poses.append(Pose(t, p.position.x, p.position.y, yaw_of(p.orientation)))
        stamp = odometry.header.stamp
        track.sim_stamps.append(stamp.sec + stamp.nanosec * 1e-9)
    elif topic == SCAN_TOPIC and kind == "sensor_msgs/msg/LaserScan":
        pose = track.pose_at(t)
        if pose is not None:
            track.scans.append(Scan(t, _scan_points(cast("LaserScan", msg), pose)))
    elif topic == ROOM_TOPIC and kind == "visualization_msgs/msg/MarkerArray":
        _room(track, cast("MarkerArray", msg))
    elif kind == TURTLE_POSE:
        turtle = cast("TurtlePose", msg)
        name = turtle_name(topic)
        track.turtles.setdefault(name, []).append(Pose(t, turtle.x, turtle.y, turtle.theta))
    elif kind == "rcl_interfaces/msg/Log":  # as ros2 run prints a node's log line
        log = cast("Log", msg)
        level = LOG_LEVELS.get(log.level, str(log.level))
        track.moments.append(Moment(t, topic, _cut(f"[{level}] [{log.name}]: {log.msg}")))
    else:
        text = json.dumps(to_plain(msg, max_items=8), separators=(", ", ": "))
        track.moments.append(Moment(t, topic, _cut(text)))


def turtle_name(topic: str) -> str:
    """``/turtle1/pose`` -> ``turtle1``; ``/sim2/turtle1/pose`` -> ``sim2/turtle1``."""
    return topic.removesuffix("/pose").strip("/") or topic


def _cut(text: str) -> str:
    return text if len(text) <= MOMENT_TEXT else text[: MOMENT_TEXT - 1] + "…"


def _scan_points(msg: LaserScan, pose: Pose) -> tuple[tuple[float, float], ...]:
    """Each return's place in the world, the scanner taken to sit at the robot's centre
    (its few centimetres of offset do not show at a room's scale)."""
    points = []
    for i, r in enumerate(msg.ranges):
        if not (math.isfinite(r) and msg.range_min <= r <= msg.range_max):
            continue
        a = pose.yaw + msg.angle_min + i * msg.angle_increment
        points.append((round(pose.x + r * math.cos(a), 3), round(pose.y + r * math.sin(a), 3)))
    return tuple(points)


def _room(track: Track, msg: MarkerArray) -> None:
    """The room from its markers: the largest flat one is the floor, the rest obstacles."""
    boxes: list[Box] = []
    floors: list[Box] = []
    for marker in msg.markers:
        if marker.action not in (0, 1):  # ADD, MODIFY
            continue
        p, s = marker.pose.position, marker.scale
        box = Box(
            f"{marker.ns}/{marker.id}",
            p.x,
            p.y,
            abs(s.x) / 2,
            abs(s.y) / 2,
            yaw_of(marker.pose.orientation),
        )
        (floors if p.z + abs(s.z) / 2 <= FLOOR_HEIGHT else boxes).append(box)
    track.room = boxes
    track.floor = max(floors, key=lambda b: b.half_x * b.half_y, default=None)
