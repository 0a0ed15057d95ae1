"""Check ``map_matches_world``: the newest /map covers the floor and agrees with the world file.

The map a mapping node publishes (nav_msgs/OccupancyGrid, latched) is laid
over the simulated world's floor plan (its walls and furniture at the
lidar's height, from the world file): **coverage** is the share of the floor
the robot can reach that the map calls free; **agreement** is the share of
the cells the map claims to know that the plan confirms (an occupied cell
has an obstacle reaching into it, a free one is not inside any). While the
learner drives, the check waits and says how far the map has come.
"""

from __future__ import annotations

import functools
import threading
from typing import TYPE_CHECKING

import numpy as np
from nav_msgs.msg import OccupancyGrid
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from app.lessons.checks._sim_topics import world_map
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check
from app.ros.monitor import TopicMonitor
from nodes.common.occupancy_grid import (
    cell_centres,
    floor_coverage,
    floor_points,
    map_agreement,
    map_values_at,
    plan_distance,
)

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

MAP = "/map"
LATCHED = QoSProfile(
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)


@functools.cache
def _floor(world: str) -> tuple[np.ndarray, np.ndarray]:
    return floor_points(world_map(world).obstacles)


class MapWatch:
    """The newest /map, latched (a map published once still arrives), and its figures."""

    def __init__(self, node: Node) -> None:
        self.monitor = TopicMonitor(node, MAP, OccupancyGrid, keep=1, qos=LATCHED)
        self._lock = threading.Lock()
        self._figured: tuple[int, str, tuple[float, float, int]] | None = None

    def figures(self, world: str) -> tuple[OccupancyGrid, float, float, int] | None:
        """(map, coverage %, agreement %, known cells) of the newest map; None before one."""
        newest = self.monitor.message()
        if newest is None:
            return None
        msg = newest[1]
        with self._lock:
            if self._figured is None or self._figured[:2] != (id(msg), world):
                self._figured = (id(msg), world, _measure(msg, world))
            coverage, agreement, known = self._figured[2]
        return msg, coverage, agreement, known

    def close(self) -> None:
        self.monitor.close()


def _measure(msg: OccupancyGrid, world: str) -> tuple[float, float, int]:
    info = msg.info
    origin = (info.origin.position.x, info.origin.position.y)
    size = (info.resolution, int(info.width), int(info.height))
    data = np.asarray(msg.data, np.int16)
    xs, ys = cell_centres(origin, *size)
    agreement = map_agreement(data, plan_distance(world_map(world).obstacles, xs, ys), size[0])
    coverage = floor_coverage(map_values_at(data, origin, *size, *_floor(world)))
    return coverage, agreement.percent, agreement.known


@register_check(
    "map_matches_world",
    required="coverage agreement",
    optional="world",
    words="the newest /map (nav_msgs/OccupancyGrid) calls at least `coverage` per cent of the "
    "floor the robot can reach free, and at least `agreement` per cent of the cells it knows "
    "agree with the world file's walls and furniture",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    world = str(c.get("world", "office"))
    found = rt.watch("map", MapWatch).figures(world)
    if found is None:
        if not rt.publishers(MAP):
            return CheckResult(
                FAIL,
                f"no publisher on {MAP}: nothing serves a map yet (a mapper or map_server does)",
            )
        return CheckResult(WAITING, f"waiting for the first map on {MAP}")
    msg, coverage, agreement, known = found
    info = msg.info
    if info.width * info.height == 0 or len(msg.data) != info.width * info.height:
        return CheckResult(FAIL, f"the map on {MAP} has no cells ({info.width} x {info.height})")
    size = f"{info.width} x {info.height} cells of {info.resolution:g} m"
    text = (
        f"the map ({size}) calls {coverage:.0f} % of the {world}'s floor free; "
        f"{agreement:.1f} % of its {known} known cells agree with the world file"
    )
    if not agreement >= float(c["agreement"]):  # NaN (nothing known) is not agreement
        if known < 100:
            return CheckResult(WAITING, f"{text}: drive, so that it sees more")
        return CheckResult(
            FAIL, f"{text}: it should be {c['agreement']} % (is the map's frame the world's?)"
        )
    if coverage < float(c["coverage"]):
        return CheckResult(WAITING, f"{text}: drive on until {c['coverage']} % is mapped")
    return CheckResult(PASS, text)
