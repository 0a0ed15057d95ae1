"""Check ``scan_nearest``: the shortest range in /scan is below a bound and matches the world."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from app.lessons.checks._sim_topics import (
    TRUTH,
    bearing_words,
    seconds,
    truth_at,
    world_map,
)
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

SCAN, SCAN_TYPE = "/scan", "sensor_msgs/msg/LaserScan"
WAY_OFF = 5.0  # tolerances: a difference this large is not noise, it is another world


@register_check(
    "scan_nearest",
    required="below tolerance",
    optional="world",
    words="the shortest range of the newest /scan is below a bound, and agrees (within the "
    "tolerance) with the distance from the scanner to the nearest obstacle in the world file, "
    "where /ground_truth/odom puts the robot",
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
    if shortest >= float(c["below"]):
        return CheckResult(WAITING, f"{text}; drive closer than {c['below']:g} m to something")
    return CheckResult(PASS, text)
