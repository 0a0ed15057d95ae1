"""Check ``sim_time_stamps``: a node stamps a TF frame with simulation time (it uses
use_sim_time), as /clock tells it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.checks._sim_topics import CLOCK, WALL_CLOCK_SECONDS, seconds
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

TF, TF_TYPE = "/tf", "tf2_msgs/msg/TFMessage"


def newest_stamp(rt: LessonRuntime, frame: str) -> tuple[float, float] | None:
    """(arrival wall time, stamp in s) of the newest transform to ``frame`` on /tf."""
    for arrival, msg in rt.tap(TF, TF_TYPE).newest():
        for t in msg.transforms:
            if t.child_frame_id == frame:
                return arrival, seconds(t.header.stamp)
    return None


@register_check(
    "sim_time_stamps",
    required="frame",
    optional="tolerance",
    words="the newest transform to a frame on /tf is stamped with simulation time: within "
    "tolerance seconds (0.5 unless given) of what /clock says",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    clock = rt.tap(CLOCK, "rosgraph_msgs/msg/Clock").message()
    if clock is None:
        if not rt.publishers(CLOCK):
            return CheckResult(FAIL, f"no publisher on {CLOCK}: start the simulation first")
        return CheckResult(WAITING, f"waiting for {CLOCK}")
    frame = c["frame"]
    seen = newest_stamp(rt, frame)
    if seen is None:
        if not rt.publishers(TF):
            return CheckResult(FAIL, "nobody publishes /tf")
        return CheckResult(WAITING, f"no transform to '{frame}' on /tf yet")
    now = seconds(clock[1].clock)
    stamp = seen[1]
    if stamp > WALL_CLOCK_SECONDS:
        return CheckResult(
            WAITING,
            f"'{frame}' is stamped {stamp:.1f} s: wall-clock time, while /clock says {now:.2f} s "
            "(the node that sends it does not use simulation time)",
        )
    text = f"'{frame}' is stamped {stamp:.2f} s and /clock says {now:.2f} s"
    if abs(stamp - now) <= float(c.get("tolerance", 0.5)):
        return CheckResult(PASS, f"{text}: its node's clock follows the simulation")
    return CheckResult(WAITING, f"{text}: not the same time yet")
