"""Probe ``log_odds_map``: feed poses and laser scans of a hidden world, judge the node's /map.

The grader draws a small world on the exercise's grid (a room with thick walls
somewhere inside the map, a few boxes in it) and a few robot poses in its free
space. For each pose it computes the laser scan a perfect scanner would see
there (exact ray and box intersections, in numpy: no simulator), publishes the
pose (``geometry_msgs/msg/PoseStamped``) and then the scan
(``sensor_msgs/msg/LaserScan``), and waits for the node's next /map before the
next pose, so that no scan can meet the wrong pose. At the end it joins /map
late (transient local, as a map user does) and judges that map:

- its frame and geometry are the statement's;
- cells no beam came near (not even a neighbouring cell) are still -1;
- among the cells the statement's log-odds rule decides (the grader runs it
  itself on the same scans), at least ``agreement`` of the node's values
  are the world's truth: 0 where the world is free, 100 where it is occupied.

When the node's map fits a known mistake much better than the right map (the
data written column by column; the beams not turned by the robot's heading),
the result says so. The world, the poses and the expected map are pure
functions of the grading's random generator (testable without ROS).
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from app.exercises.probes.base import ProbeContext, draw, register_probe
from app.exercises.probes.topics import (
    listen,
    publishers_note,
    wait_matched,
    with_note,
)
from app.exercises.report import Result
from app.lessons.schema import Spec

if TYPE_CHECKING:
    from geometry_msgs.msg import PoseStamped
    from nav_msgs.msg import OccupancyGrid
    from sensor_msgs.msg import LaserScan

# The statement's log-odds rule.
HIT, MISS = 0.85, -0.4
L_MIN, L_MAX = -2.0, 3.5
OCCUPIED_ABOVE = math.log(0.65 / 0.35)  # p > 0.65: 100
FREE_BELOW = math.log(0.25 / 0.75)  # p < 0.25: 0
PAST_SURFACE = 0.02  # m: the grader's ranges reach this far into what they hit
RANGE_MIN, RANGE_MAX = 0.05, 10.0
WALL = 2  # cells: the room's walls are this thick
Cell = tuple[int, int]  # (column, row): column along x, row along y


@dataclass(frozen=True)
class Frame:
    """Where the grid lies in the map frame, and its size in cells."""

    width: int
    height: int
    resolution: float
    x: float
    y: float

    def cell_of(self, x: float, y: float) -> Cell:
        return math.floor((x - self.x) / self.resolution), math.floor(
            (y - self.y) / self.resolution
        )

    def inside(self, col: int, row: int) -> bool:
        return 0 <= col < self.width and 0 <= row < self.height


@dataclass(frozen=True)
class Box:
    """Cells ``c0..c1`` by ``r0..r1`` (both ends included), all occupied."""

    c0: int
    r0: int
    c1: int
    r1: int


@dataclass(frozen=True)
class World:
    frame: Frame
    boxes: tuple[Box, ...]  # the room's four walls first, then the boxes in it
    room: Box  # the free floor inside the walls

    def truth(self) -> np.ndarray:
        """Occupied cells, (height, width) bool, row 0 first."""
        grid = np.zeros((self.frame.height, self.frame.width), bool)
        for b in self.boxes:
            grid[b.r0 : b.r1 + 1, b.c0 : b.c1 + 1] = True
        return grid


@dataclass(frozen=True)
class Scan:
    """One pose of the robot and what its scanner saw there (float32, as the message)."""

    x: float
    y: float
    yaw: float
    angle_min: float
    angle_increment: float
    ranges: tuple[float, ...]


def make_world(rng: random.Random, frame: Frame, boxes: int) -> World:
    """A room with walls ``WALL`` cells thick, a few cells inside the map's edges, and
    ``boxes`` boxes on its floor, apart from the walls and from each other."""
    w, h = frame.width, frame.height
    c0, c1 = rng.randint(2, 6), w - 1 - rng.randint(2, 6)
    r0, r1 = rng.randint(2, 5), h - 1 - rng.randint(2, 5)
    walls = [
        Box(c0, r0, c1, r0 + WALL - 1),
        Box(c0, r1 - WALL + 1, c1, r1),
        Box(c0, r0, c0 + WALL - 1, r1),
        Box(c1 - WALL + 1, r0, c1, r1),
    ]
    room = Box(c0 + WALL, r0 + WALL, c1 - WALL, r1 - WALL)
    placed: list[Box] = []
    for _ in range(200):
        if len(placed) == boxes:
            break
        bw, bh = rng.randint(3, 7), rng.randint(3, 7)
        bc = rng.randint(room.c0 + 4, room.c1 - 4 - bw + 1)
        br = rng.randint(room.r0 + 4, room.r1 - 4 - bh + 1)
        box = Box(bc, br, bc + bw - 1, br + bh - 1)
        if all(
            box.c0 > o.c1 + 3 or box.c1 < o.c0 - 3 or box.r0 > o.r1 + 3 or box.r1 < o.r0 - 3
            for o in placed
        ):
            placed.append(box)
    return World(frame, tuple(walls + placed), room)


def make_poses(rng: random.Random, world: World, count: int) -> list[tuple[float, float, float]]:
    """``count`` poses on the free floor, 0.35 m clear of everything and 0.6 m apart."""
    f, room, occupied = world.frame, world.room, world.truth()
    clear = int(math.ceil(0.35 / f.resolution))
    poses: list[tuple[float, float, float]] = []
    for _ in range(2000):
        if len(poses) == count:
            break
        x = rng.uniform(f.x + room.c0 * f.resolution, f.x + (room.c1 + 1) * f.resolution)
        y = rng.uniform(f.y + room.r0 * f.resolution, f.y + (room.r1 + 1) * f.resolution)
        col, row = f.cell_of(x, y)
        near = occupied[
            max(row - clear, 0) : row + clear + 1, max(col - clear, 0) : col + clear + 1
        ]
        if near.any() or any(math.hypot(x - px, y - py) < 0.6 for px, py, _ in poses):
            continue
        poses.append((round(x, 3), round(y, 3), round(rng.uniform(-math.pi, math.pi), 3)))
    if len(poses) < count:
        raise ValueError(f"no room for {count} poses in the drawn world")
    return poses


def scan_at(world: World, pose: tuple[float, float, float], beams: int) -> Scan:
    """The scan a perfect scanner at ``pose`` sees: each range is the distance to the first
    box the beam meets, plus ``PAST_SURFACE`` (so the beam ends inside that box's cell)."""
    f = world.frame
    angle_min = float(np.float32(-math.pi))
    increment = float(np.float32(2.0 * math.pi / beams))
    x, y, yaw = pose
    angles = yaw + angle_min + np.arange(beams) * increment
    dx, dy = np.cos(angles), np.sin(angles)
    lo = np.array([[f.x + b.c0 * f.resolution, f.y + b.r0 * f.resolution] for b in world.boxes])
    hi = np.array(
        [[f.x + (b.c1 + 1) * f.resolution, f.y + (b.r1 + 1) * f.resolution] for b in world.boxes]
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        tx1, tx2 = (lo[None, :, 0] - x) / dx[:, None], (hi[None, :, 0] - x) / dx[:, None]
        ty1, ty2 = (lo[None, :, 1] - y) / dy[:, None], (hi[None, :, 1] - y) / dy[:, None]
    t_in = np.maximum(np.fmin(tx1, tx2), np.fmin(ty1, ty2))
    t_out = np.minimum(np.fmax(tx1, tx2), np.fmax(ty1, ty2))
    t = np.where((t_out >= t_in) & (t_in > 0.0), t_in, np.inf).min(axis=1)
    ranges = np.where(np.isfinite(t), t + PAST_SURFACE, np.inf).astype(np.float32)
    return Scan(x, y, yaw, angle_min, increment, tuple(float(r) for r in ranges))


def line_cells(c0: int, r0: int, c1: int, r1: int) -> list[Cell]:
    """Bresenham's line from (c0, r0) to (c1, r1), both included (the statement's helper)."""
    dc, dr = abs(c1 - c0), -abs(r1 - r0)
    sc, sr = (1 if c1 > c0 else -1), (1 if r1 > r0 else -1)
    err = dc + dr
    cells = []
    while True:
        cells.append((c0, r0))
        if c0 == c1 and r0 == r1:
            return cells
        e2 = 2 * err
        if e2 >= dr:
            err += dr
            c0 += sc
        if e2 <= dc:
            err += dc
            r0 += sr


def scan_cells(frame: Frame, scan: Scan, heading: bool = True) -> tuple[set[Cell], set[Cell]]:
    """The cells beams of one scan end in (hits) and pass through (misses, hits left out).

    ``heading`` False: the beams are not turned by the robot's yaw (a learner's mistake).
    """
    hits: set[Cell] = set()
    passed: set[Cell] = set()
    start = frame.cell_of(scan.x, scan.y)
    yaw = scan.yaw if heading else 0.0
    for i, r in enumerate(scan.ranges):
        if not (math.isfinite(r) and RANGE_MIN <= r <= RANGE_MAX):
            continue
        angle = yaw + scan.angle_min + i * scan.angle_increment
        end = frame.cell_of(scan.x + r * math.cos(angle), scan.y + r * math.sin(angle))
        cells = line_cells(*start, *end)
        passed.update(c for c in cells[:-1] if frame.inside(*c))
        if frame.inside(*end):
            hits.add(end)
    return hits, passed - hits


def expected_map(
    frame: Frame, scans: Sequence[Scan], heading: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """The statement's rule run on the scans: the map (-1/0/100, (height, width)) and the
    cells any beam touched."""
    log_odds = np.zeros((frame.height, frame.width))
    touched = np.zeros((frame.height, frame.width), bool)
    for scan in scans:
        hits, misses = scan_cells(frame, scan, heading)
        for cells, change in ((misses, MISS), (hits, HIT)):
            if cells:
                cols, rows = np.array(sorted(cells)).T
                log_odds[rows, cols] = np.clip(log_odds[rows, cols] + change, L_MIN, L_MAX)
                touched[rows, cols] = True
    grid = np.full(log_odds.shape, -1, np.int64)
    grid[log_odds < FREE_BELOW] = 0
    grid[log_odds > OCCUPIED_ABOVE] = 100
    return grid, touched


def _near(cells: np.ndarray) -> np.ndarray:
    """``cells`` and their 8 neighbours."""
    grown = cells.copy()
    padded = np.pad(cells, 1)
    h, w = cells.shape
    for dr in (0, 1, 2):
        for dc in (0, 1, 2):
            grown |= padded[dr : dr + h, dc : dc + w]
    return grown


def _match(mine: np.ndarray, other: np.ndarray) -> float:
    """How alike two maps are where either knows something (0 when neither does)."""
    known = (mine != -1) | (other != -1)
    return float((mine[known] == other[known]).mean()) if known.any() else 0.0


@dataclass(frozen=True)
class Task:
    """What a grading draws: the world and the scans, and what they tell."""

    world: World
    scans: tuple[Scan, ...]


def draw_task(rng: random.Random, frame: Frame, boxes: int, poses: int, beams: int) -> Task:
    """A world and the scans at ``poses`` poses in it (another world where they do not fit)."""
    for _ in range(50):
        world = make_world(rng, frame, boxes)
        try:
            drawn = make_poses(rng, world, poses)
        except ValueError:
            continue
        return Task(world, tuple(scan_at(world, pose, beams) for pose in drawn))
    raise ValueError(f"no world with room for {poses} poses could be drawn")


def judge_map(
    task: Task,
    frame_id: str,
    info: tuple[int, int, float, float, float],
    data: Sequence[int],
    agreement: float,
    unknown: float,
) -> tuple[str, str]:
    """(why the map breaks the contract or '' when it keeps it, what was found).

    ``info`` is the map's (width, height, resolution, origin x, origin y).
    """
    f = task.world.frame
    want = (f.width, f.height, f.resolution, f.x, f.y)
    if frame_id != "map":
        return f"the map's header.frame_id is {frame_id!r}; it must be 'map'", ""
    width, height, resolution, ox, oy = info
    if (width, height) != (f.width, f.height) or not all(
        math.isclose(a, b, abs_tol=1e-6) for a, b in zip(info[2:], want[2:], strict=True)
    ):
        return (
            f"the map is {width} x {height} cells of {resolution:g} m at origin "
            f"({ox:g}, {oy:g}); the statement's is {f.width} x {f.height} cells of "
            f"{f.resolution:g} m at ({f.x:g}, {f.y:g})",
            "",
        )
    if len(data) != f.width * f.height:
        return f"the map's data has {len(data)} values for {f.width} x {f.height} cells", ""
    mine = np.asarray(data, np.int64).reshape(f.height, f.width)
    expected, touched = expected_map(f, task.scans)
    decided = expected != -1
    truth = np.where(task.world.truth(), 100, 0)
    right = float((mine[decided] == truth[decided]).mean())
    found = f"{right:.0%} of the {int(decided.sum())} cells the scans decide agree with the world"
    why = _looks_like(f, task, mine, expected)
    if why:
        return why, found
    far = ~_near(touched)
    wrong_far = far & (mine != -1)
    if wrong_far.sum() > (1.0 - unknown) * far.sum():
        return (
            f"{int(wrong_far.sum())} of the {int(far.sum())} cells no beam came near are not -1 "
            f"({int((mine[far] == 0).sum())} are 0, {int((mine[far] == 100).sum())} are 100): "
            "a cell no beam reached is unknown, and must stay -1",
            found,
        )
    if right >= agreement:
        return "", found
    free, occupied = decided & (truth == 0), decided & (truth == 100)
    counts = (
        f"of the {int(free.sum())} free cells beams passed through, "
        f"{int((mine[free] == 0).sum())} are 0, {int((mine[free] == -1).sum())} are -1 and "
        f"{int((mine[free] == 100).sum())} are 100; of the {int(occupied.sum())} occupied cells "
        f"beams ended in, {int((mine[occupied] == 100).sum())} are 100"
    )
    hint = ""
    if (mine[free] == -1).mean() > 0.5:
        hint = (
            ": the cells a beam passes through stay -1, yet a beam that passes through a cell "
            f"is evidence that it is free (add {MISS:g} to it)"
        )
    elif (mine[occupied] == 100).mean() < 0.5:
        hint = f": a beam that ends in a cell is evidence that it is occupied (add {HIT:g})"
    return (
        f"only {right:.0%} of the {int(decided.sum())} cells the scans decide agree with the "
        f"world (at least {agreement:.0%} must): {counts}{hint}",
        found,
    )


def _looks_like(f: Frame, task: Task, mine: np.ndarray, expected: np.ndarray) -> str:
    """Why the map fits a known mistake far better than the right map ('' when it does not)."""
    right = _match(mine, expected)
    column_major = mine.reshape(f.width, f.height).T  # the data read column by column
    if _match(column_major, expected) > max(0.8, right + 0.3):
        return (
            "your map holds the right cells in the wrong order: read column by column it "
            "fits the scans, but data goes row after row, the cell (col, row) at "
            "data[row * width + col]"
        )
    unturned, _ = expected_map(f, task.scans, heading=False)
    if _match(mine, unturned) > max(0.8, right + 0.3):
        return (
            "your map is what the scans give when the beams are not turned by the robot's "
            "heading: a beam's angle in the map is the robot's yaw + angle_min + "
            "i * angle_increment"
        )
    return ""


def messages(scan: Scan, number: int) -> tuple[PoseStamped, LaserScan]:
    """The ``PoseStamped`` and the ``LaserScan`` the grader sends for one scan, stamped
    ``number`` s."""
    from geometry_msgs.msg import PoseStamped
    from sensor_msgs.msg import LaserScan

    pose = PoseStamped()
    pose.header.frame_id = "map"
    pose.header.stamp.sec = number
    pose.pose.position.x, pose.pose.position.y = scan.x, scan.y
    pose.pose.orientation.z = math.sin(scan.yaw / 2.0)
    pose.pose.orientation.w = math.cos(scan.yaw / 2.0)
    msg = LaserScan()
    msg.header.frame_id = "base_link"
    msg.header.stamp.sec = number
    msg.angle_min, msg.angle_increment = scan.angle_min, scan.angle_increment
    msg.angle_max = scan.angle_min + (len(scan.ranges) - 1) * scan.angle_increment
    msg.range_min, msg.range_max = RANGE_MIN, RANGE_MAX
    msg.ranges = list(scan.ranges)
    return pose, msg


def map_info(grid: OccupancyGrid) -> tuple[int, int, float, float, float]:
    """An OccupancyGrid's (width, height, resolution, origin x, origin y)."""
    info = grid.info
    return (
        info.width,
        info.height,
        info.resolution,
        info.origin.position.x,
        info.origin.position.y,
    )


@register_probe(
    "log_odds_map",
    required="",
    optional="scan pose topic",
    defaults={
        "width": 60,
        "height": 40,
        "resolution": 0.1,
        "origin_x": -3.0,
        "origin_y": -2.0,
        "beams": 180,
        "boxes": [2, 4],
        "poses": [5, 7],
        "agreement": 0.9,
        "unknown": 0.98,
        "within": 4.0,
    },
    words="publishes robot poses and the laser scans a hidden world gives there, then joins "
    "/map late: cells no beam came near must be -1, and of the cells the log-odds rule "
    "decides, at least the agreement share must be the world's truth (0 free, 100 occupied)",
    draws="a random room with a few boxes, the robot's poses in it (position and heading), "
    "and so the scans",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    from geometry_msgs.msg import PoseStamped
    from nav_msgs.msg import OccupancyGrid
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import LaserScan

    from app.ros.monitor import TopicMonitor

    scan_topic, pose_topic = p.get("scan", "/scan"), p.get("pose", "/robot_pose")
    topic = p.get("topic", "/map")
    frame = Frame(
        int(p["width"]),
        int(p["height"]),
        float(p["resolution"]),
        float(p["origin_x"]),
        float(p["origin_y"]),
    )
    task = draw_task(
        ctx.rng,
        frame,
        int(draw(ctx.rng, p["boxes"])),
        int(draw(ctx.rng, p["poses"])),
        int(p["beams"]),
    )
    name = f"the map on {topic} from {pose_topic} and {scan_topic}"
    node = ctx.call.node
    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    pose_pub = node.create_publisher(PoseStamped, pose_topic, reliable)
    scan_pub = node.create_publisher(LaserScan, scan_topic, reliable)
    live = listen(ctx, topic, OccupancyGrid)
    late = None
    try:
        waited = wait_matched(ctx, ((pose_pub, pose_topic), (scan_pub, scan_topic)), topic)
        if waited:
            return Result(name, False, waited)
        for number, scan in enumerate(task.scans, start=1):
            pose, msg = messages(scan, number)
            seen = live.count
            pose_pub.publish(pose)
            ctx.call.sleep(0.1)  # the pose is taken before the scan comes
            scan_pub.publish(msg)
            # The next pose waits for this scan's map: no scan may meet the wrong pose. The
            # first map may miss our reader (its writer still discovering it): 3 s is pace
            # enough then, and the late subscriber below reads what counts.
            if not live.wait_for_count(seen + 1, 3.0) and (
                number > 1 or not node.count_publishers(topic)
            ):
                text = (
                    f"sent pose {number} ({scan.x:.2f}, {scan.y:.2f}, yaw {scan.yaw:.2f}) and its "
                    f"scan; no map came on {topic} within 3 s: publish the map after each scan"
                )
                return Result(name, False, with_note(text, publishers_note(node, topic, _TYPE)))
        sent = f"sent {len(task.scans)} poses and scans"
        volatile = publishers_note(node, topic, _TYPE, "transient_local")
        if volatile:
            return Result(
                name,
                False,
                f"{sent}; a map user joining {topic} later gets nothing: {volatile}",
            )
        late_qos = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        late = TopicMonitor(node, topic, OccupancyGrid, keep=1, qos=late_qos)
        within = float(p["within"])
        if not late.wait_for_count(1, within):
            return Result(
                name,
                False,
                f"{sent}; a subscriber that joined {topic} later got no map within {within:g} s",
            )
        got = late.message(1)
        assert got is not None
        grid = got[1]
        why, found = judge_map(
            task,
            grid.header.frame_id,
            map_info(grid),
            grid.data,
            float(p["agreement"]),
            float(p["unknown"]),
        )
        if why:
            return Result(name, False, f"{sent}; the map a late subscriber got: {why}")
        return Result(name, True, f"{sent}; the map a late subscriber got: {found}")
    finally:
        live.close()
        if late is not None:
            late.close()
        node.destroy_publisher(pose_pub)
        node.destroy_publisher(scan_pub)


_TYPE = "nav_msgs/msg/OccupancyGrid"
