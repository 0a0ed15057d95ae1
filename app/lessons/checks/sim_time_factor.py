"""Check ``sim_time_factor``: simulated time runs at the factor the world reports achieving,
judged on the world's own wall clock, whatever the computer's speed.

A world asked for ``real_time_factor`` 2 runs twice as fast as the wall clock
only if the computer keeps up; a slow or busy one reaches less (1.6x on two
loaded cores), and says so on ``/real_time_factor``. So the check measures
simulated seconds per wall-clock second from ``/clock`` (each sample stamped
with the world's wall clock), asks that this agrees with what the world
reports, and that it is at least ``at_least``; against the ``requested``
factor it only chooses its words: "as asked", or "your computer runs the world
at 1.6x of the 2x asked".
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.checks._sim_speed import (
    REPORTS,
    STILL,
    SimSpeed,
    factor_text,
    speed_watch_of,
)
from app.lessons.checks._sim_topics import CLOCK, SIM_NODE
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

AGREE = 0.1  # /clock and the world's reports agree within 10 % (+ 0.05): same span, same clock
AS_ASKED = 0.1  # within 10 % of the requested factor is "as asked"
DEFAULT_AT_LEAST = 0.1  # unless given: simulated time runs at all
DEFAULT_SECONDS = 2.0


def verdict(speed: SimSpeed, requested: float, at_least: float) -> tuple[str, str]:
    """(state, words) for a measured speed; pure, so each sentence is tested without ROS."""
    f, r = speed.measured, speed.reported
    asked = factor_text(requested)
    how = f"/clock over {speed.wall_span:.1f} s: {f:.2f}x; the world reports {r:.2f}x"
    if f < STILL and r < STILL:
        return FAIL, "simulated time stands still: the world is paused (call /unpause_physics)"
    if abs(f - r) > AGREE * max(f, r) + 0.05:
        return FAIL, (
            f"simulated time on {CLOCK} runs at {f:.2f}x the wall clock, but the world "
            f"reports {r:.2f}x on {REPORTS}: they should agree ({speed.samples} samples "
            f"over {speed.wall_span:.1f} s)"
        )
    if f < at_least:
        if at_least >= 1.0:
            return FAIL, (
                f"simulated time runs at {f:.2f}x the wall clock, not clearly faster "
                f"(at least {factor_text(at_least)}; {asked} asked). Is real_time_factor "
                f"{requested:g}? If it is, your computer cannot run the world faster "
                f"than this ({how})"
            )
        return FAIL, f"simulated time runs at {f:.2f}x the wall clock, below {at_least:g}x ({how})"
    if f > requested * (1 + AS_ASKED) + 0.05:
        return FAIL, (
            f"simulated time runs at {factor_text(f)} the wall clock, faster than the "
            f"{asked} asked: is real_time_factor {requested:g}? ({how})"
        )
    if f >= requested * (1 - AS_ASKED):
        return PASS, f"simulated time runs at {factor_text(f)} the wall clock, as asked ({how})"
    pace = (
        "simulated time still runs faster than the wall clock"
        if f > 1.0
        else "simulated time still runs, slower than the wall clock"
    )
    return PASS, (f"your computer runs the world at {f:.1f}x of the {asked} asked; {pace} ({how})")


@register_check(
    "sim_time_factor",
    required="requested",
    optional="at_least seconds",
    words="simulated time (/clock) runs at the factor the world reports achieving on "
    "/real_time_factor, and at least at_least (0.1 unless given) times as fast as the "
    "wall clock, judged on the world's own clock over seconds (2 unless given); a computer "
    "too slow for the requested factor passes, and is told so",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    if not rt.graph.has_node(SIM_NODE):
        return CheckResult(FAIL, f"{SIM_NODE} is not running: start the world first")
    watch = speed_watch_of(rt)
    speed = watch.speed(float(c.get("seconds", DEFAULT_SECONDS)))
    if isinstance(speed, str):
        return CheckResult(WAITING, f"measuring how fast simulated time runs: {speed}")
    state, text = verdict(speed, float(c["requested"]), float(c.get("at_least", DEFAULT_AT_LEAST)))
    if watch.by_arrival:
        text += " (by arrival times: the middleware gave no publisher timestamps)"
    return CheckResult(state, text)
