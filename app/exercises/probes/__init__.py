"""Probes: the grader drives the learner's node and judges what comes back.

A check only looks at the graph; a probe gives the node input and compares
the answer. Each probe kind is one module here that registers itself with
``register_probe`` (``app.exercises.probes.base``), as the lessons' check
kinds do: its fields (the loader validates exercise files against them), its
code, and its words for the learner and for `exercise explain`. To add a
kind, add ``app/exercises/probes/<kind>.py``; nothing else is edited::

    from app.exercises.probes.base import ProbeContext, register_probe
    from app.exercises.report import Result
    from app.lessons.schema import Spec


    @register_probe("topic_echo", required="publish output", optional="count",
                    words="what is published on one topic comes back on the other")
    def run(ctx: ProbeContext, p: Spec) -> Result:
        ...  # bounded in time; say what was tried and what came back

Modules that register nothing hold what several kinds share: ``base`` (the
registry, context, formulas, comparisons), ``exchange`` (send an input on a
topic, read the answer to it) and ``tf`` (frame maths and a /tf reader).
"""

from __future__ import annotations

from app.exercises.probes.base import PROBES, Probe, ProbeContext, ProbeKind
from app.exercises.report import Result
from app.lessons.kinds import Kind
from app.lessons.registry import import_all
from app.lessons.schema import Spec
from app.ros.errors import Ros2Error

import_all(__name__, __path__)

# Each kind's fields, by name, as the exercise loader reads them.
PROBE_KINDS: dict[str, Kind] = {name: kind.fields for name, kind in PROBES.items()}

__all__ = ["PROBES", "PROBE_KINDS", "Probe", "ProbeContext", "ProbeKind", "run_probe"]


def run_probe(ctx: ProbeContext, probe: Spec) -> Result:
    """One probe; any error becomes a failed result with its message."""
    try:
        return PROBES[probe.kind].run(ctx, probe)
    except (Ros2Error, ValueError, KeyError, TypeError, AttributeError) as exc:
        return Result(probe.kind, False, f"{type(exc).__name__}: {exc}")
