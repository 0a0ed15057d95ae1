"""Probe ``program_args``: run the learner's program again with drawn command-line arguments
(as ``ros2 run pkg client 5 7`` would) and read what it and the setup nodes log.

``args`` names the arguments in order, each a range or a list of words;
``log`` lists lines the program must print and ``setup_log`` lines one of the
setup nodes must print, each a template whose braced formulas use the drawn
arguments (``"{a} + {b} = {a + b}"``). With ``setup_after``, the setup nodes
are stopped first and started only that long after the program (drawn too):
a client must wait for its server.
"""

from __future__ import annotations

import time

from app.exercises.probes.base import (
    ProbeContext,
    draw,
    fill_template,
    register_probe,
    values_text,
)
from app.exercises.report import Result
from app.lessons.schema import Spec


def _found(lines: list[str], wanted: list[str]) -> list[str]:
    """The wanted texts that no line contains."""
    return [w for w in wanted if not any(w in line for line in lines)]


@register_probe(
    "program_args",
    required="args",
    optional="log setup_log setup_after",
    defaults={"within": 10.0},
    words="runs your program again with random command-line arguments (the setup nodes "
    "starting only later, when setup_after is given, so it must wait for them); its output "
    "and the setup nodes' must show lines that follow from the arguments",
    draws="the command-line arguments (args), and how long the setup nodes start after "
    "the program (setup_after)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    if ctx.programs is None:
        raise ValueError("program_args needs a grading that may restart the learner's program")
    programs = ctx.programs
    values = {name: draw(ctx.rng, value) for name, value in p["args"].items()}
    argv = [str(v) for v in values.values()]
    shown = " ".join(argv)
    name = f"your program run with arguments {shown}"
    want_log = [fill_template(t, values) for t in p.get("log", [])]
    want_setup = [fill_template(t, values) for t in p.get("setup_log", [])]
    delay = float(draw(ctx.rng, p["setup_after"])) if "setup_after" in p.fields else None
    if delay is not None:
        programs.stop_setup()
    programs.restart_learner(argv)
    started = time.monotonic()
    if delay is not None:
        while time.monotonic() - started < delay:
            if not programs.learner_alive():
                break
            ctx.call.sleep(0.1)
        if not programs.learner_alive():
            tail = "\n".join(programs.learner_output()[-6:])
            return Result(
                name,
                False,
                f"your program ended before the service it needs was there (started "
                f"{delay:.1f} s later): wait for it\n{tail}",
            )
        programs.start_setup()
    within = float(p["within"])
    deadline = time.monotonic() + within
    while True:
        missing_setup = _found(
            [ln for out in programs.setup_output().values() for ln in out], want_setup
        )
        missing = _found(programs.learner_output(), want_log)
        if not missing_setup and not missing:
            break
        if time.monotonic() > deadline or not programs.learner_alive():
            after = f" within {within:g} s" + (
                f" of the setup nodes' start ({delay:.1f} s after your program)"
                if delay is not None
                else ""
            )
            if missing_setup:
                return Result(
                    name,
                    False,
                    f"{values_text(values)}: no setup node logged a line containing "
                    f"{missing_setup[0]!r}{after}: did your request reach it?",
                )
            ended = "" if programs.learner_alive() else " (and it has ended)"
            return Result(
                name,
                False,
                f"{values_text(values)}: its output has no line containing {missing[0]!r}"
                f"{after}{ended}",
            )
        ctx.call.sleep(0.2)
    waited = f"; the server started {delay:.1f} s after it" if delay is not None else ""
    return Result(name, True, f"it printed {', '.join(repr(w) for w in want_log)}{waited}")
