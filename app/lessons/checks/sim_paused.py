"""Check ``sim_paused``: simulation time stands still: /clock has gone quiet while the
simulation runs (and a node on simulation time has stopped sending a frame, if given).
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from app.lessons.checks._sim_speed import REPORTS, STILL, speed_watch_of
from app.lessons.checks._sim_topics import CLOCK, SIM_NODE, seconds
from app.lessons.checks.sim_time_stamps import newest_stamp
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

DISCOVERY_SEC = 4.0  # a fresh subscription may hear nothing this long (Fast DDS discovery)


@register_check(
    "sim_paused",
    required="",
    optional="quiet frame",
    words="simulation time stands still: no /clock for quiet seconds (1 unless given) while "
    "/sim_world runs and reports 0x on /real_time_factor, and, if a frame is named, no new "
    "transform to it either (a node on simulation time waits)",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    if not rt.graph.has_node(SIM_NODE):
        return CheckResult(FAIL, f"{SIM_NODE} is not running: nothing to pause")
    quiet = float(c.get("quiet", 1.0))
    key = (CLOCK, "rosgraph_msgs/msg/Clock")
    tap = rt.tap(*key)
    newest = tap.message()
    now = time.time()
    if newest is None:
        listened = time.monotonic() - rt.tap_born.get(key, time.monotonic())
        if listened < quiet + DISCOVERY_SEC:
            return CheckResult(WAITING, f"listening to {CLOCK} for {listened:.1f} s")
        text = f"no {CLOCK} message in the {listened:.1f} s since this check began listening"
    else:
        silent = now - newest[0]
        if silent < quiet:
            return CheckResult(
                WAITING,
                f"{CLOCK} still ticks: {seconds(newest[1].clock):.2f} s of simulation time",
            )
        text = f"no {CLOCK} for {silent:.1f} s: simulation time stands at "
        text += f"{seconds(newest[1].clock):.2f} s"
    # A world that gets no CPU (a loaded computer) sends no /clock either: only its own
    # report, 0x over a whole second, tells that time was stopped (a 2 s stall passed).
    report = speed_watch_of(rt).newest_report()
    if report is None or report.factor >= STILL:
        said = "nothing yet" if report is None else f"{report.factor:.2f}x"
        return CheckResult(
            WAITING,
            f"{text}, but the world does not report simulated time standing still on "
            f"{REPORTS} ({said}): a busy computer can hold up /clock too",
        )
    frame = c.get("frame")
    if frame:
        seen = newest_stamp(rt, frame)
        if seen is not None and now - seen[0] < quiet:
            return CheckResult(WAITING, f"{text}, but '{frame}' is still sent")
        if seen is not None:
            text += f"; '{frame}' was last sent {now - seen[0]:.1f} s ago, stamped {seen[1]:.2f} s"
        else:
            text += f"; no '{frame}' heard"
    return CheckResult(PASS, text)
