"""The floor plan of a sim_world world, read from its MJCF file, and the robot's footprint.

The simulation checks and the simulation probes judge the robot against the
room it drives in: how far the nearest wall is, what lies straight ahead,
whether the body touches anything. They read the same world file the
simulation loads (``nodes/worlds/<name>/world.xml``) with a plain XML parse,
never the simulation's own state, so a lesson's verdict does not depend on
the code it judges.

The plan is two-dimensional: every fixed geom (directly in ``<worldbody>``,
in a ``<frame>`` or in a body without joints) whose height overlaps the
robot's body (``BODY_BAND``) becomes a rectangle (box) or a circle
(cylinder, sphere, upright capsule). Free objects (a body with a joint) and
the robots (``<attach>``) are left out: they move. Geoms turned about another
axis than z cannot be drawn on a floor plan and are listed in ``skipped``.

No ROS and no MuJoCo here: plain geometry, testable alone.
"""

from __future__ import annotations

import functools
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from app import PROJECT_ROOT
from app.ros.planar import Box

WORLDS_DIR = PROJECT_ROOT / "nodes" / "worlds"
BODY_BAND = (0.02, 0.2)  # m above the floor: the diffbot's chassis, wheels and scanner
# The diffbot's outline around base_link (nodes/robots/diffbot/robot.xml): the chassis
# runs from x = -0.11 to 0.07 m, the wheels stick out to y = +-0.089 m.
FOOTPRINT = (-0.11, 0.07, -0.09, 0.09)  # x_min, x_max, y_min, y_max in base_link
# Every point of the body lies this close to base_link (its farthest corner).
BODY_RADIUS = max(math.hypot(x, y) for x in FOOTPRINT[:2] for y in FOOTPRINT[2:])
_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_-]*$")


class WorldMapError(ValueError):
    """A world file that cannot be read as a floor plan; the message says why."""


@dataclass(frozen=True)
class Circle:
    name: str
    x: float
    y: float
    radius: float

    def distance(self, px: float, py: float) -> float:
        return math.hypot(px - self.x, py - self.y) - self.radius

    def ray(self, px: float, py: float, angle: float) -> float:
        dx, dy = math.cos(angle), math.sin(angle)
        ox, oy = px - self.x, py - self.y
        b = ox * dx + oy * dy
        c = ox * ox + oy * oy - self.radius**2
        disc = b * b - c
        if disc < 0:
            return math.inf
        root = math.sqrt(disc)
        for t in (-b - root, -b + root):
            if t >= 0:
                return t if c > 0 else 0.0
        return math.inf


Obstacle = Box | Circle


@dataclass(frozen=True)
class Nearest:
    """The closest obstacle to something: how far, which, and the bearing to it."""

    distance: float
    name: str
    bearing: float = 0.0  # rad, in the robot's frame (0 ahead, +pi/2 to the left)


_Shape = tuple[list[tuple[float, float]] | None, float, float, float]


@dataclass(frozen=True)
class WorldMap:
    """The fixed obstacles of a world at the robot's height, in the world frame."""

    path: Path
    obstacles: tuple[Obstacle, ...]
    skipped: tuple[str, ...] = field(default=())

    def nearest(self, x: float, y: float) -> Nearest:
        """The obstacle closest to a point (for the scanner: its position)."""
        best = Nearest(math.inf, "")
        for obstacle in self.obstacles:
            d = obstacle.distance(x, y)
            if d < best.distance:
                best = Nearest(d, obstacle.name)
        return best

    def ray(self, x: float, y: float, angle: float) -> Nearest:
        """The first obstacle along a ray from (x, y) at ``angle`` (world frame)."""
        best = Nearest(math.inf, "")
        for obstacle in self.obstacles:
            d = obstacle.ray(x, y, angle)
            if d < best.distance:
                best = Nearest(d, obstacle.name)
        return best

    def nearest_on_side(
        self, x: float, y: float, yaw: float, low: float, high: float, step: float = 0.01
    ) -> Nearest:
        """The closest obstacle seen at a bearing between ``low`` and ``high`` (rad, robot frame).

        Rays every ``step`` radians, as a scanner would see it without noise.
        """
        best = Nearest(math.inf, "")
        count = max(2, int((high - low) / step) + 1)
        for k in range(count):
            bearing = low + (high - low) * k / (count - 1)
            hit = self.ray(x, y, yaw + bearing)
            if hit.distance < best.distance:
                best = Nearest(hit.distance, hit.name, bearing)
        return best

    @functools.cached_property
    def _shapes(self) -> tuple[_Shape, ...]:
        """Per obstacle: its corners (None: a circle) and a circle around it (x, y, radius)."""
        out: list[_Shape] = []
        for obstacle in self.obstacles:
            if isinstance(obstacle, Circle):
                out.append((None, obstacle.x, obstacle.y, obstacle.radius))
                continue
            corners = obstacle.corners()
            cx = sum(px for px, _ in corners) / len(corners)
            cy = sum(py for _, py in corners) / len(corners)
            out.append((corners, cx, cy, max(math.dist(c, (cx, cy)) for c in corners)))
        return tuple(out)

    def clearance(self, x: float, y: float, yaw: float) -> Nearest:
        """How far the robot's body (FOOTPRINT at this pose) is from the closest obstacle.

        Zero or less: the body touches or overlaps it.
        """
        body = footprint(x, y, yaw)

        def gap(k: int) -> float:
            corners, cx, cy, radius = self._shapes[k]
            if corners is None:
                return _polygon_point_distance(body, (cx, cy)) - radius
            return _polygon_distance(body, corners)

        # Called for every ground-truth sample: obstacles whose surrounding circle lies
        # farther than one exact gap (the obstacle nearest by centre) cannot be the closest,
        # and are not measured. The same answer as measuring all, at a tenth of the cost.
        lows = [math.hypot(cx - x, cy - y) - r - BODY_RADIUS for _, cx, cy, r in self._shapes]
        limit = gap(min(range(len(lows)), key=lows.__getitem__)) if lows else math.inf
        best = Nearest(math.inf, "")
        for k, obstacle in enumerate(self.obstacles):
            if lows[k] > limit:
                continue
            d = gap(k)
            if d < best.distance:
                best = Nearest(d, obstacle.name)
        return best

    def names(self) -> list[str]:
        return [o.name for o in self.obstacles]


def footprint(x: float, y: float, yaw: float) -> list[tuple[float, float]]:
    """The corners of the robot's outline at a pose, counter-clockwise."""
    x0, x1, y0, y1 = FOOTPRINT
    c, s = math.cos(yaw), math.sin(yaw)
    corners = ((x1, y0), (x1, y1), (x0, y1), (x0, y0))
    return [(x + c * px - s * py, y + s * px + c * py) for px, py in corners]


def _segment_distance(p: tuple[float, float], a: tuple[float, float], b: tuple[float, float]):
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / length2))
    return math.hypot(p[0] - (ax + t * dx), p[1] - (ay + t * dy))


def _inside(p: tuple[float, float], polygon: list[tuple[float, float]]) -> bool:
    """Inside a convex polygon given counter-clockwise or clockwise."""
    signs = set()
    for i, a in enumerate(polygon):
        b = polygon[(i + 1) % len(polygon)]
        cross = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
        if abs(cross) > 1e-12:
            signs.add(cross > 0)
    return len(signs) <= 1


def _polygon_point_distance(polygon: list[tuple[float, float]], p: tuple[float, float]) -> float:
    """Distance from a point to a convex polygon; negative (its depth) inside."""
    edge = min(
        _segment_distance(p, a, polygon[(i + 1) % len(polygon)]) for i, a in enumerate(polygon)
    )
    return -edge if _inside(p, polygon) else edge


def _polygon_distance(a: list[tuple[float, float]], b: list[tuple[float, float]]) -> float:
    """Distance between two convex polygons; 0 when they touch or overlap."""
    if any(_inside(p, b) for p in a) or any(_inside(p, a) for p in b):
        return 0.0
    if _edges_cross(a, b):
        return 0.0
    return min(
        min(_segment_distance(p, q, poly[(i + 1) % len(poly)]) for i, q in enumerate(poly))
        for points, poly in ((a, b), (b, a))
        for p in points
    )


def _edges_cross(a: list[tuple[float, float]], b: list[tuple[float, float]]) -> bool:
    def orient(p, q, r) -> float:
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    for i, p1 in enumerate(a):
        p2 = a[(i + 1) % len(a)]
        for j, q1 in enumerate(b):
            q2 = b[(j + 1) % len(b)]
            d1, d2 = orient(q1, q2, p1), orient(q1, q2, p2)
            d3, d4 = orient(p1, p2, q1), orient(p1, p2, q2)
            if d1 * d2 < 0 and d3 * d4 < 0:
                return True
    return False


# ------------------------------------------------------------------ reading the MJCF file


def world_file(world: str) -> Path:
    """``room`` -> nodes/worlds/room/world.xml; a path ending in .xml is taken as given."""
    if world.endswith(".xml"):
        path = Path(world).expanduser()
    elif _NAME.match(world):
        path = WORLDS_DIR / world / "world.xml"
    else:
        raise WorldMapError(f"world {world!r} is neither a world name nor a path to an .xml file")
    if not path.is_file():
        raise WorldMapError(f"world file {path} does not exist")
    return path


def _floats(text: str | None, count: int, default: tuple[float, ...]) -> tuple[float, ...]:
    if text is None:
        return default
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        raise WorldMapError(f"not a list of numbers: {text!r}") from None
    return values[:count] if len(values) >= count else values + default[len(values) :]


def _class_defaults(root: ET.Element) -> dict[str, dict[str, str]]:
    """Each default class's geom attributes, inherited from the classes around it."""
    found: dict[str, dict[str, str]] = {}

    def walk(element: ET.Element, inherited: dict[str, str]) -> None:
        geom = element.find("geom")
        attrs = {**inherited, **(geom.attrib if geom is not None else {})}
        found[element.get("class", "main")] = attrs
        for child in element.findall("default"):
            walk(child, attrs)

    for top in root.findall("default"):
        walk(top, {})
    return found


def _yaw_of(attrs: dict[str, str], degrees: bool) -> float | None:
    """The turn about z given by euler or quat; None for a turn about another axis."""
    if "euler" in attrs:
        rx, ry, rz = _floats(attrs["euler"], 3, (0.0, 0.0, 0.0))
        scale = math.pi / 180.0 if degrees else 1.0
        if abs(rx) > 1e-6 or abs(ry) > 1e-6:
            return None
        return rz * scale
    if "quat" in attrs:
        w, qx, qy, qz = _floats(attrs["quat"], 4, (1.0, 0.0, 0.0, 0.0))
        if abs(qx) > 1e-6 or abs(qy) > 1e-6:
            return None
        return 2.0 * math.atan2(qz, w)
    if any(key in attrs for key in ("axisangle", "xyaxes", "zaxis", "fromto")):
        return None
    return 0.0


def load_world_map(world: str = "room") -> WorldMap:
    """The floor plan of a world: its fixed geoms at the robot's height."""
    path = world_file(world)
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise WorldMapError(f"world file {path} is not valid XML: {exc}") from None
    compiler = root.find("compiler")
    degrees = compiler is None or compiler.get("angle", "degree") != "radian"
    defaults = _class_defaults(root)
    worldbody = root.find("worldbody")
    if worldbody is None:
        raise WorldMapError(f"world file {path} has no <worldbody>")
    obstacles: list[Obstacle] = []
    skipped: list[str] = []

    def visit(element: ET.Element, ox: float, oy: float, oz: float, oyaw: float) -> None:
        for child in element:
            if child.tag in ("frame", "body"):
                if child.tag == "body" and (
                    child.find("joint") is not None or child.find("freejoint") is not None
                ):
                    continue  # it moves: not part of the floor plan
                px, py, pz = _floats(child.get("pos"), 3, (0.0, 0.0, 0.0))
                turn = _yaw_of(child.attrib, degrees)
                if turn is None:
                    skipped.append(f"{child.tag} {child.get('name', '?')} (tilted)")
                    continue
                c, s = math.cos(oyaw), math.sin(oyaw)
                visit(child, ox + c * px - s * py, oy + s * px + c * py, oz + pz, oyaw + turn)
            elif child.tag == "geom":
                _add_geom(child, (ox, oy, oz, oyaw), defaults, degrees, obstacles, skipped)

    visit(worldbody, 0.0, 0.0, 0.0, 0.0)
    return WorldMap(path, tuple(obstacles), tuple(skipped))


def _add_geom(
    geom: ET.Element,
    origin: tuple[float, float, float, float],
    defaults: dict[str, dict[str, str]],
    degrees: bool,
    obstacles: list[Obstacle],
    skipped: list[str],
) -> None:
    attrs = {**defaults.get("main", {}), **defaults.get(geom.get("class", "main"), {})}
    attrs.update(geom.attrib)
    kind = attrs.get("type", "sphere")
    name = attrs.get("name", f"{kind}_{len(obstacles)}")
    if kind == "plane" or (attrs.get("contype") == "0" and attrs.get("conaffinity") == "0"):
        return
    ox, oy, oz, oyaw = origin
    px, py, pz = _floats(attrs.get("pos"), 3, (0.0, 0.0, 0.0))
    c, s = math.cos(oyaw), math.sin(oyaw)
    x, y, z = ox + c * px - s * py, oy + s * px + c * py, oz + pz
    turn = _yaw_of(attrs, degrees)
    size = _floats(attrs.get("size"), 3, (0.0, 0.0, 0.0))
    if turn is None:
        skipped.append(f"geom {name} (turned about x or y)")
        return
    if kind == "box":
        half_height = size[2]
    elif kind in ("cylinder", "capsule"):
        half_height = size[1] + (size[0] if kind == "capsule" else 0.0)
    elif kind == "sphere":
        half_height = size[0]
    else:
        skipped.append(f"geom {name} (type {kind})")
        return
    if z + half_height < BODY_BAND[0] or z - half_height > BODY_BAND[1]:
        return  # above or below the robot
    if kind == "box":
        obstacles.append(Box(name, x, y, size[0], size[1], oyaw + turn))
    else:
        obstacles.append(Circle(name, x, y, size[0]))
