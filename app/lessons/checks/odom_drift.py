"""Check ``odom_drift``: /odom beside /ground_truth/odom after a drive: how far apart they are.

``at_least`` and ``turned`` are how far the drive takes the robot at real time; when
the computer ran the world slower while it drove, the same commands took it that
share as far (see _sim_drive), and that share is asked.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from app.lessons.checks._sim_drive import newest_drive_of
from app.lessons.checks._sim_topics import (
    ODOM,
    ODOM_TYPE,
    TRUTH,
    pose_of,
    relative,
    truth_at,
    wrap,
)
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "odom_drift",
    required="at_least",
    optional="turned x y yaw max_error",
    words="once the robot is at least so many metres (and, if given, turned radians) away "
    "from its start pose (x, y, yaw: the odom frame's origin since the last reset), /odom "
    "and /ground_truth/odom of the same instant are compared: how far apart they are, and "
    "never more than max_error if given; when the computer ran the world slower than real "
    "time during the drive, that share of the distance and turn is asked",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    newest = rt.tap(ODOM, ODOM_TYPE).message()
    for topic, message in ((ODOM, newest), (TRUTH, rt.tap(TRUTH, ODOM_TYPE).message())):
        if message is None:
            if not rt.publishers(topic):
                return CheckResult(FAIL, f"no publisher on {topic}: is the simulation running?")
            return CheckResult(WAITING, f"waiting for a message on {topic}")
    assert newest is not None
    odom = pose_of(newest[1])
    truth = truth_at(rt, odom.t)
    if truth is None:
        return CheckResult(WAITING, f"no {TRUTH} message of the same instant as /odom yet")
    start = (float(c.get("x", 0.0)), float(c.get("y", 0.0)), float(c.get("yaw", 0.0)))
    seen = relative(start, truth)  # where odometry would be if it never drifted
    moved, turned = math.hypot(seen.x, seen.y), abs(seen.yaw)
    far, turn_needed = float(c["at_least"]), float(c.get("turned", 0.0))
    drive, slower = newest_drive_of(rt), ""
    if drive is not None and drive.slower_words():
        far, turn_needed = far * drive.share, turn_needed * drive.share
        slower = f" ({drive.slower_words()})"
    if moved < far or turned < turn_needed:
        need = f"{far:.2f} m away" + (f", turned {turn_needed:.2f} rad" if turn_needed else "")
        return CheckResult(
            WAITING,
            f"the robot is {moved:.2f} m from its start, turned {turned:.2f} rad; "
            f"drive until it is {need}{slower}",
        )
    error = math.hypot(odom.x - seen.x, odom.y - seen.y)
    turn = abs(wrap(odom.yaw - seen.yaw))
    text = (
        f"at t={odom.t:.1f} s, /odom says {odom.text()} and the ground truth (seen from the "
        f"start) is {seen.text()}: {error * 100:.1f} cm and {math.degrees(turn):.1f} deg apart "
        f"after {moved:.2f} m{slower}"
    )
    if "max_error" in c.fields and error > float(c["max_error"]):
        return CheckResult(
            FAIL, f"{text}; more than {c['max_error']:g} m: was the world reset before the drive?"
        )
    return CheckResult(PASS, text)
