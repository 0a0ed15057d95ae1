"""Probe ``param_set``: set a parameter; it is accepted (and its effect seen) or refused."""

from __future__ import annotations

import time

from app.exercises.probes.base import (
    ProbeContext,
    draw,
    expected_value,
    fill_template,
    register_probe,
    without_kind,
)
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros import params
from app.ros.errors import Ros2Error

RATE_JUDGED_SEC = 4.0  # a rate that follows a drawn value is judged on this long of messages


@register_probe(
    "param_set",
    required="name value accept",
    optional="node reason_contains then within",
    words="sets a parameter (to a random value where a range or a list of words is given); "
    "the node must accept it and show its effect (a check, which may name the value as "
    "{value}), or refuse it with a reason",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    target, pname, value = p.get("node", ctx.learner_node), p["name"], draw(ctx.rng, p["value"])
    name = f"parameter {pname}={value!r}"
    try:
        ok, reason = params.set_value(ctx.call, target, pname, value)
        answered = time.monotonic()  # a rate judged after this hears only the new setting
    except Ros2Error as exc:
        return Result(name, False, str(exc))
    if not p["accept"]:
        if ok:
            return Result(name, False, f"{target} accepted {pname}={value!r}; it should refuse it")
        if not reason.strip():
            return Result(name, False, f"{target} refused {pname}={value!r} but gave no reason")
        needed = p.get("reason_contains", "")
        if needed and needed.lower() not in reason.lower():
            return Result(
                name, False, f"refused with reason {reason!r}; it should mention {needed!r}"
            )
        return Result(name, True, f"refused, with the reason {reason!r}")
    if not ok:
        return Result(name, False, f"{target} refused {pname}={value!r}: {reason or 'no reason'}")
    then = p.get("then")
    if then is None:
        return Result(name, True, f"{target} accepted {pname}={value!r}")
    # "{value}" in a text of the check is the value set ("I heard: {value} from").
    check = {
        k: fill_template(v, {"value": value}) if isinstance(v, str) and k != "expect_hz" else v
        for k, v in without_kind(then).items()
    }
    if "expect_hz" in check:
        # A rate that follows the drawn value: the window is derived from it.
        hz = float(expected_value(check.pop("expect_hz"), {"value": value}))
        spread = float(check.pop("rate_tolerance", 0.1))
        check["min_hz"], check["max_hz"] = round(hz * (1 - spread), 3), round(hz * (1 + spread), 3)
        check.setdefault("samples", max(8, round(hz * RATE_JUDGED_SEC)))
        # Only what was sent after the node answered: the grader's tap heard the old rate
        # too, and a window holding both read 8.987 Hz as 8.58 Hz.
        check["since"] = answered
    passed, detail = ctx.wait_check(Spec(then["kind"], check), p.get("within", 10.0))
    verdict = "then " + detail
    return Result(name, passed, f"accepted; {verdict}")
