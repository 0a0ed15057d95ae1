"""Check ``scan_nearest``: the shortest range in /scan is below a bound and matches the world.

``below`` is where a drive at real time brings the robot. When the computer ran the
world slower while the robot drove (see _sim_drive), the same commands took it only
that share of the way: then the range straight ahead must have come that share of
the way down from where the drive began towards ``below`` (the nearest thing may be
off to the side on the way, so the shortest range alone would not tell).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from app.lessons.checks._sim_drive import newest_drive_of
from app.lessons.checks._sim_topics import (
    TRUTH,
    bearing_words,
    seconds,
    truth_at,
    world_map,
)
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from sensor_msgs.msg import LaserScan

    from app.lessons.checks._sim_drive import Drive
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

SCAN, SCAN_TYPE = "/scan", "sensor_msgs/msg/LaserScan"
WAY_OFF = 5.0  # tolerances: a difference this large is not noise, it is another world
AHEAD_RAYS = 3  # each side of straight ahead: the closest of them is the range ahead


@register_check(
    "scan_nearest",
    required="below tolerance",
    optional="world",
    words="the shortest range of the newest /scan is below a bound, and agrees (within the "
    "tolerance) with the distance from the scanner to the nearest obstacle in the world file, "
    "where /ground_truth/odom puts the robot; when the computer ran the world slower than real "
    "time during the drive, the range straight ahead came that share of the way down to the "
    "bound",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    newest = rt.tap(SCAN, SCAN_TYPE).message()
    if newest is None:
        if not rt.publishers(SCAN):
            return CheckResult(FAIL, f"no publisher on {SCAN}: is the simulation running?")
        return CheckResult(WAITING, f"waiting for a message on {SCAN}")
    scan = newest[1]
    shortest, index = math.inf, -1
    for i, r in enumerate(scan.ranges):
        r = scan.range_min if r == -math.inf else r  # -inf: closer than the scanner measures
        if math.isfinite(r) and r < shortest:
            shortest, index = r, i
    if index < 0:
        return CheckResult(WAITING, "the newest scan saw nothing within its range")
    stamp = seconds(scan.header.stamp)
    pose = truth_at(rt, stamp)
    if pose is None:
        return CheckResult(WAITING, f"no {TRUTH} message of the scan's instant yet")
    nearest = world_map(c.get("world", "room")).nearest(pose.x, pose.y)
    angle = scan.angle_min + index * scan.angle_increment
    text = (
        f"the shortest range is ranges[{index}] = {shortest:.2f} m at {bearing_words(angle)}; "
        f"the world file puts {nearest.name} {nearest.distance:.2f} m from the scanner"
    )
    gap = abs(shortest - nearest.distance)
    if gap > WAY_OFF * float(c["tolerance"]):
        return CheckResult(FAIL, f"{text}: they disagree (is another world loaded?)")
    if gap > float(c["tolerance"]):
        return CheckResult(WAITING, f"{text}; they differ by {gap:.2f} m")
    if shortest < float(c["below"]):
        return CheckResult(PASS, text)
    drive = newest_drive_of(rt)
    if drive is None or not drive.slower_words():
        return CheckResult(WAITING, f"{text}; drive closer than {c['below']:g} m to something")
    return _share_of_the_way(c, scan, drive, text)


def _share_of_the_way(c: Spec, scan: LaserScan, drive: Drive, text: str) -> CheckResult:
    """A drive slowed by the computer: the range ahead came its share of the way down."""
    start = drive.start
    before = world_map(c.get("world", "room")).ray(start.x, start.y, start.yaw).distance
    ahead = _range_ahead(scan)
    needed = before - max(0.0, before - float(c["below"])) * drive.share
    said = (
        f"{text}; {drive.slower_words()}: straight ahead the laser reads {ahead:.2f} m, "
        f"{before:.2f} m where the drive began"
    )
    if ahead < needed:
        return CheckResult(PASS, f"{said}, closer than {needed:.2f} m (that share of the way)")
    return CheckResult(WAITING, f"{said}; drive on until it is closer than {needed:.2f} m")


def _range_ahead(scan: LaserScan) -> float:
    """The closest of the rays either side of straight ahead (inf: nothing in range)."""
    centre = round(-scan.angle_min / scan.angle_increment) if scan.angle_increment else 0
    rays = (
        [
            scan.ranges[i % len(scan.ranges)]
            for i in range(centre - AHEAD_RAYS, centre + AHEAD_RAYS + 1)
        ]
        if scan.ranges
        else []
    )
    # -inf: closer than the scanner measures
    found = [scan.range_min if r == -math.inf else r for r in rays if not math.isnan(r)]
    found = [r for r in found if math.isfinite(r)]
    return min(found, default=math.inf)
