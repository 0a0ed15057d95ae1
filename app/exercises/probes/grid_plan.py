"""Probe ``grid_plan``: publish a random occupancy grid on /map, ask the node for plans.

The grader latches a random map (``nav_msgs/msg/OccupancyGrid``, transient
local, as Nav2's map_server does): a thick wall across the grid with one door
and a stretch nobody has seen (-1), random obstacles of values 50 to 100, and
a closed room. It then calls the node's ``nav_msgs/srv/GetPlan`` service with
start and goal points on the free cells and judges each plan on the grid:
starts in the start's cell, ends in the goal's, every step to a neighbouring
cell (8-connected, a diagonal step only where both cells beside it are free:
no cutting corners, as NavFn), never on a blocked cell, and at most
``max_ratio`` times as long as the shortest such path (the grader's own
Dijkstra). A goal in the closed room has no path: the plan must be empty.

The requests are chosen so that each shortcut a planner must not take would
pay off on at least one of them: through a wall, through the unknown, round a
corner, and staying on 4 neighbours would cost more than ``max_ratio``. The
map and the requests are pure functions of the grading's random generator
(testable without ROS).
"""

from __future__ import annotations

import heapq
import math
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from app.exercises.probes.base import ProbeContext, draw, register_probe
from app.exercises.probes.topics import wait_delivered, wait_subscribed
from app.exercises.report import Result
from app.exercises.trace import Trace
from app.lessons.schema import Spec
from app.ros.calls import call_service
from app.ros.errors import Ros2Error

SQRT2 = math.sqrt(2.0)
UNKNOWN, OCCUPIED = -1, 100
OBSTACLE_VALUES = (50, 65, 80, 100, 100)  # what a SLAM map calls occupied: 50 and above
Cell = tuple[int, int]  # (column, row): column along x, row along y


def is_free(value: int) -> bool:
    """The statement's rule: 0 to 49 is free; -1 (unknown) and 50 or more are blocked."""
    return 0 <= value < 50


@dataclass(frozen=True)
class Grid:
    """An occupancy grid as the message holds it: row by row from the origin, row 0 first."""

    width: int
    height: int
    data: tuple[int, ...]

    def value(self, cell: Cell) -> int:
        return self.data[cell[1] * self.width + cell[0]]

    def inside(self, cell: Cell) -> bool:
        return 0 <= cell[0] < self.width and 0 <= cell[1] < self.height

    def cells(self) -> list[Cell]:
        return [(c, r) for r in range(self.height) for c in range(self.width)]


def shortest(
    grid: Grid,
    start: Cell,
    goal: Cell,
    free: Callable[[int], bool] = is_free,
    *,
    diagonal: bool = True,
    cut_corners: bool = False,
) -> float:
    """The length (in cells) of the shortest path, math.inf when there is none.

    The statement's rule by default; the other arguments give the rules a
    wrong planner follows (to choose requests on which it would differ).
    """
    if not (grid.inside(start) and grid.inside(goal)):
        return math.inf
    if not (free(grid.value(start)) and free(grid.value(goal))):
        return math.inf
    moves = [(1, 0, 1.0), (-1, 0, 1.0), (0, 1, 1.0), (0, -1, 1.0)]
    if diagonal:
        moves += [(1, 1, SQRT2), (1, -1, SQRT2), (-1, 1, SQRT2), (-1, -1, SQRT2)]
    ok = [free(v) for v in grid.data]
    w, h = grid.width, grid.height
    best = {start: 0.0}
    heap = [(0.0, start)]
    while heap:
        cost, (c, r) = heapq.heappop(heap)
        if (c, r) == goal:
            return cost
        if cost > best[(c, r)]:
            continue
        for dc, dr, step in moves:
            nc, nr = c + dc, r + dr
            if not (0 <= nc < w and 0 <= nr < h) or not ok[nr * w + nc]:
                continue
            if dc and dr and not cut_corners and not (ok[r * w + nc] and ok[nr * w + c]):
                continue
            new = cost + step
            if new < best.get((nc, nr), math.inf) - 1e-9:
                best[(nc, nr)] = new
                heapq.heappush(heap, (new, (nc, nr)))
    return math.inf


def octile(a: Cell, b: Cell) -> float:
    dc, dr = abs(a[0] - b[0]), abs(a[1] - b[1])
    return max(dc, dr) + (SQRT2 - 1.0) * min(dc, dr)


def _component(grid: Grid, seed: Cell) -> set[Cell]:
    """The free cells reachable from ``seed`` by the statement's rule."""
    seen, todo = {seed}, [seed]
    while todo:
        c, r = todo.pop()
        for dc in (-1, 0, 1):
            for dr in (-1, 0, 1):
                n = (c + dc, r + dr)
                if n in seen or not grid.inside(n) or not is_free(grid.value(n)):
                    continue
                if (
                    dc
                    and dr
                    and not (is_free(grid.value((c + dc, r))) and is_free(grid.value((c, r + dr))))
                ):
                    continue
                seen.add(n)
                todo.append(n)
    return seen


@dataclass(frozen=True)
class World:
    """A drawn map, its closed room's inside, and the side of the wall each column is on."""

    grid: Grid
    room: tuple[Cell, ...]  # free cells no path reaches
    main: tuple[Cell, ...]  # the largest region of free cells joined by paths
    wall: tuple[int, int]  # the wall's first and last column


def make_world(rng: random.Random, width: int, height: int) -> World:
    """A random map: a wall with a door and an unknown stretch, obstacles, a closed room."""
    for _ in range(200):
        world = _draw_world(rng, width, height)
        if world is not None:
            return world
    raise ValueError(f"no map of {width} x {height} cells could be drawn")


def _draw_world(rng: random.Random, width: int, height: int) -> World | None:
    rows = [[0] * width for _ in range(height)]

    def fill(c0: int, r0: int, c1: int, r1: int, value: int) -> None:
        for r in range(max(r0, 0), min(r1, height - 1) + 1):
            for c in range(max(c0, 0), min(c1, width - 1) + 1):
                rows[r][c] = value

    wall = rng.randint(width * 2 // 5, width * 3 // 5)
    fill(wall, 0, wall + 1, height - 1, OCCUPIED)
    door = rng.randint(1, height - 5)
    fill(wall, door, wall + 1, door + 2, 0)
    # Behind the wall nobody looked: a stretch of it is unknown, away from the door.
    length = rng.randint(5, 8)
    spots = [r for r in range(0, height - length + 1) if r + length < door - 2 or r > door + 5]
    if not spots:
        return None
    hidden = rng.choice(spots)
    fill(wall, hidden, wall + 1, hidden + length - 1, UNKNOWN)
    # A closed room on one side of the wall: its inside has no way in.
    room_w, room_h = rng.randint(6, 8), rng.randint(5, 7)
    left = rng.random() < 0.5
    c0 = rng.randint(1, wall - room_w - 2) if left else rng.randint(wall + 3, width - room_w - 1)
    r0 = rng.randint(1, height - room_h - 1)
    c1, r1 = c0 + room_w - 1, r0 + room_h - 1
    fill(c0, r0, c1, r1, OCCUPIED)
    fill(c0 + 1, r0 + 1, c1 - 1, r1 - 1, 0)
    # Obstacles, clear of the room and of the door.
    for _ in range(rng.randint(5, 8)):
        w, h = rng.randint(2, 6), rng.randint(2, 5)
        oc, orow = rng.randint(0, width - w), rng.randint(0, height - h)
        if oc <= c1 + 1 and oc + w - 1 >= c0 - 1 and orow <= r1 + 1 and orow + h - 1 >= r0 - 1:
            continue
        if oc <= wall + 3 and oc + w - 1 >= wall - 2 and orow <= door + 4 and orow + h >= door - 2:
            continue
        fill(oc, orow, oc + w - 1, orow + h - 1, rng.choice(OBSTACLE_VALUES))
    # An unexplored corner of the map, now and then.
    if rng.random() < 0.5:
        fill(0, height - rng.randint(2, 4), rng.randint(3, 6), height - 1, UNKNOWN)
    grid = Grid(width, height, tuple(v for row in rows for v in row))
    room = tuple(
        (c, r) for r in range(r0 + 1, r1) for c in range(c0 + 1, c1) if is_free(grid.value((c, r)))
    )
    main: set[Cell] = set()
    for cell in grid.cells():
        if is_free(grid.value(cell)) and cell not in main and cell not in room:
            region = _component(grid, cell)
            if len(region) > len(main):
                main = region
    sides = {c < wall for c, _ in main}
    if not room or sides != {True, False} or len(main) < width * height // 3:
        return None
    return World(grid, room, tuple(sorted(main)), (wall, wall + 1))


@dataclass(frozen=True)
class Request:
    start: Cell
    goal: Cell
    optimal: float  # cells; math.inf: no path


def choose_requests(
    rng: random.Random, world: World, reachable: int, unreachable: int, max_ratio: float
) -> list[Request] | None:
    """Start and goal cells across the wall; the unreachable ones (a goal in the closed room)
    last. Among the reachable ones, each shortcut a wrong planner might take pays off at
    least once (None when 60 candidates do not manage it: draw another map)."""
    grid, main = world.grid, world.main
    left = [c for c in main if c[0] < world.wall[0]]
    right = [c for c in main if c[0] > world.wall[1]]
    covers = {
        "through walls": lambda s, g, best: shortest(grid, s, g, lambda v: True) < best - 0.5,
        "through unknown": lambda s, g, best: shortest(grid, s, g, lambda v: v < 50) < best - 0.5,
        "round corners": lambda s, g, best: shortest(grid, s, g, cut_corners=True) < best - 1e-6,
        "4 neighbours": lambda s, g, best: (
            shortest(grid, s, g, diagonal=False) > max_ratio * best + 0.5
        ),
    }
    chosen: list[Request] = []
    missing = set(covers)
    spare: list[Request] = []
    for _ in range(60):
        a, b = rng.choice(left), rng.choice(right)
        start, goal = (a, b) if rng.random() < 0.5 else (b, a)
        best = shortest(grid, start, goal)
        if not math.isfinite(best) or octile(start, goal) < 8:
            continue
        hits = {name for name in missing if covers[name](start, goal, best)}
        if hits and len(chosen) < reachable:
            chosen.append(Request(start, goal, best))
            missing -= hits
        else:
            spare.append(Request(start, goal, best))
        if not missing and len(chosen) + len(spare) >= reachable:
            break
    if missing:
        return None
    chosen += spare[: max(0, reachable - len(chosen))]
    rng.shuffle(chosen)
    for _ in range(unreachable):
        a, b = rng.choice(main), rng.choice(world.room)
        start, goal = (a, b) if rng.random() < 0.5 else (b, a)
        chosen.append(Request(start, goal, math.inf))
    return chosen


def draw_task(
    rng: random.Random,
    width: int,
    height: int,
    reachable: int,
    unreachable: int,
    max_ratio: float,
) -> tuple[World, list[Request]]:
    """A map and the requests to plan on it (``choose_requests``)."""
    for _ in range(50):
        world = make_world(rng, width, height)
        requests = choose_requests(rng, world, reachable, unreachable, max_ratio)
        if requests is not None:
            return world, requests
    raise ValueError("no map with requests that tell planners apart could be drawn")


@dataclass(frozen=True)
class Frame:
    """Where the grid lies in the map frame."""

    x: float
    y: float
    resolution: float

    def cell_of(self, x: float, y: float) -> Cell:
        return (
            math.floor((x - self.x) / self.resolution),
            math.floor((y - self.y) / self.resolution),
        )

    def point_in(self, cell: Cell, rng: random.Random) -> tuple[float, float]:
        """A point well inside ``cell`` (not its centre: a learner must floor, not round)."""
        jx, jy = rng.uniform(0.2, 0.8), rng.uniform(0.2, 0.8)
        return self.x + (cell[0] + jx) * self.resolution, self.y + (cell[1] + jy) * self.resolution


def _value_words(value: int) -> str:
    return "value -1: unknown" if value == UNKNOWN else f"value {value}: occupied"


def judge_plan(
    grid: Grid,
    frame: Frame,
    request: Request,
    frame_id: str,
    points: Sequence[tuple[float, float]],
    max_ratio: float,
) -> tuple[str, float]:
    """Why the plan breaks the contract ('' when it keeps it), and its length over the
    shortest (nan where that means nothing: no path, or a plan broken otherwise)."""
    why, walked = _walk(grid, frame, request, frame_id, points)
    if why or not math.isfinite(request.optimal):
        return why, math.nan
    ratio = walked / request.optimal
    if ratio > max_ratio + 1e-9:
        why = (
            f"the plan is {walked * frame.resolution:.2f} m long, longer than the shortest "
            f"path ({request.optimal * frame.resolution:.2f} m) times {max_ratio:g}"
        )
    return why, ratio


def _walk(
    grid: Grid,
    frame: Frame,
    request: Request,
    frame_id: str,
    points: Sequence[tuple[float, float]],
) -> tuple[str, float]:
    """Why the plan breaks a rule of the grid ('' when it does not), and its length in cells."""
    if points and frame_id != "map":
        return (
            f"the plan's header.frame_id is {frame_id!r}; it must be 'map', the frame its "
            "poses are in",
            math.nan,
        )
    if not math.isfinite(request.optimal):
        if points:
            return (
                f"no path exists (one of the two points is inside a closed room), yet the plan has "
                f"{len(points)} poses: expected an empty plan",
                math.nan,
            )
        return "", 0.0
    length = request.optimal * frame.resolution
    if not points:
        return f"the plan is empty, but a path of {length:.2f} m exists", 0.0
    cells = [frame.cell_of(x, y) for x, y in points]
    if cells[0] != request.start:
        return (
            f"the plan begins at ({points[0][0]:.2f}, {points[0][1]:.2f}), cell {cells[0]}, "
            f"not in the start's cell {request.start}",
            math.nan,
        )
    if cells[-1] != request.goal:
        return (
            f"the plan ends at ({points[-1][0]:.2f}, {points[-1][1]:.2f}), cell {cells[-1]}, "
            f"not in the goal's cell {request.goal}",
            math.nan,
        )
    walked = 0.0
    for i, (cell, (x, y)) in enumerate(zip(cells, points, strict=True)):
        where = f"pose {i} at ({x:.2f}, {y:.2f}), cell {cell},"
        if not grid.inside(cell):
            return f"{where} is outside the map", math.nan
        if not is_free(grid.value(cell)):
            return f"{where} is on a blocked cell ({_value_words(grid.value(cell))})", math.nan
        if i == 0:
            continue
        before = cells[i - 1]
        dc, dr = cell[0] - before[0], cell[1] - before[1]
        if max(abs(dc), abs(dr)) > 1:
            return f"the plan jumps from cell {before} to cell {cell} (pose {i})", math.nan
        if dc and dr:
            for side in ((cell[0], before[1]), (before[0], cell[1])):
                if not is_free(grid.value(side)):
                    return (
                        f"the diagonal step from cell {before} to {cell} (pose {i}) cuts the "
                        f"corner of blocked cell {side} ({_value_words(grid.value(side))})",
                        math.nan,
                    )
        walked += math.hypot(dc, dr)
    return "", walked


@register_probe(
    "grid_plan",
    required="service",
    optional="topic",
    defaults={
        "width": 40,
        "height": 30,
        "resolution": 0.1,
        "origin_x": [-3.0, -1.0],
        "origin_y": [-2.0, -0.5],
        "requests": 4,
        "unreachable": 1,
        "max_ratio": 1.05,
    },
    words="latches a random occupancy grid on /map and asks the node's GetPlan service for "
    "paths between random free cells: each plan must start and end in the right cells, step "
    "only to free neighbours (8-connected, no cutting corners), be at most max_ratio times "
    "the shortest, and be empty where no path exists",
    draws="a random map (a wall with a door and an unknown stretch, obstacles of values 50 "
    "to 100, a closed room) at a random origin, start and goal points inside free cells",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    from nav_msgs.msg import OccupancyGrid
    from nav_msgs.srv import GetPlan
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    service, topic = p["service"], p.get("topic", "/map")
    max_ratio = float(p["max_ratio"])
    width, height = int(p["width"]), int(p["height"])
    frame = Frame(
        round(float(draw(ctx.rng, p["origin_x"])), 2),
        round(float(draw(ctx.rng, p["origin_y"])), 2),
        float(p["resolution"]),
    )
    world, requests = draw_task(
        ctx.rng, width, height, int(p["requests"]), int(p["unreachable"]), max_ratio
    )
    grid = world.grid
    name = f"plans from {service} on {topic}"

    node = ctx.call.node
    latched = QoSProfile(
        depth=1,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
        reliability=ReliabilityPolicy.RELIABLE,
    )
    publisher = node.create_publisher(OccupancyGrid, topic, latched)
    points: list[tuple[float, float]] = []  # (request number, length / shortest) to plot

    def plotted(broken_at: float | None = None, why: str = "") -> tuple[Trace, ...]:
        if not points:
            return ()
        return (
            Trace.of(
                "plan length / shortest path length, per request with a path",
                "ratio",
                points,
                high=max_ratio,
                broken_at=broken_at,
                broken_why=why,
                along="request",
            ),
        )

    try:
        grid_msg = OccupancyGrid()
        grid_msg.header.frame_id = "map"
        grid_msg.header.stamp = node.get_clock().now().to_msg()
        grid_msg.info.map_load_time = grid_msg.header.stamp
        grid_msg.info.resolution = frame.resolution
        grid_msg.info.width, grid_msg.info.height = width, height
        grid_msg.info.origin.position.x, grid_msg.info.origin.position.y = frame.x, frame.y
        grid_msg.info.origin.orientation.w = 1.0
        grid_msg.data = list(grid.data)
        publisher.publish(grid_msg)
        waited = wait_subscribed(ctx, publisher, topic)
        if waited:
            return Result(name, False, waited)
        # The node answers from the map it holds, so the requests wait for its subscription
        # to acknowledge the latched map (a loaded machine once took over 1.8 s: "no map
        # yet" on the first request and on its retry), then a little for its callback.
        wait_delivered(ctx, publisher)
        ctx.call.sleep(0.5)
        told = (
            f"map {width} x {height} cells of {frame.resolution:g} m, origin "
            f"({frame.x:.2f}, {frame.y:.2f})"
        )
        done: list[str] = []
        for number, request in enumerate(requests, start=1):
            sx, sy = frame.point_in(request.start, ctx.rng)
            gx, gy = frame.point_in(request.goal, ctx.rng)
            asked = GetPlan.Request()
            for pose, (x, y) in ((asked.start, (sx, sy)), (asked.goal, (gx, gy))):
                pose.header.frame_id = "map"
                pose.pose.position.x, pose.pose.position.y = x, y
                pose.pose.orientation.w = 1.0
            asked.tolerance = 0.0
            what = (
                f"request {number}: start ({sx:.2f}, {sy:.2f}) cell {request.start}, "
                f"goal ({gx:.2f}, {gy:.2f}) cell {request.goal}"
            )
            for attempt in range(2):
                try:
                    answer = call_service(
                        ctx.call, service, GetPlan, asked, timeout=3.0, resend_unanswered=True
                    )
                except Ros2Error as exc:
                    return Result(
                        name, False, f"{what}: {exc}", plotted(float(number), "no answer")
                    )
                plan = answer.plan  # type: ignore[attr-defined]
                # A node may answer before the latched map reached it: the first time, once.
                if plan.poses or number > 1 or attempt or not math.isfinite(request.optimal):
                    break
                ctx.call.sleep(1.0)
            got = [(pose.pose.position.x, pose.pose.position.y) for pose in plan.poses]
            why, ratio = judge_plan(grid, frame, request, plan.header.frame_id, got, max_ratio)
            if math.isfinite(ratio):
                points.append((float(number), ratio))
            if why:
                return Result(
                    name, False, f"{told}; {what}: {why}", plotted(float(number), why[:40])
                )
            done.append(
                f"{len(got)} poses, {ratio:.3f} x the shortest" if got else "empty (no path)"
            )
        return Result(name, True, f"{told}; {len(done)} plans right: {'; '.join(done)}", plotted())
    finally:
        node.destroy_publisher(publisher)
