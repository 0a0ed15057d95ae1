"""Probes: the grader drives the learner's node and judges what comes back.

A check only looks at the graph; a probe gives the node input and compares
the answer. The kinds live in topic modules (``core``, ``perception``,
``behaviour``); this registry joins them. Each module exports ``KINDS`` (the
fields the loader validates) and ``PROBES`` (the code).
"""

from __future__ import annotations

from app.exercises.probes import behaviour, core, perception, tf
from app.exercises.probes.base import Probe, ProbeContext
from app.exercises.report import Result
from app.lessons.kinds import Kind
from app.lessons.schema import Spec
from app.ros.errors import Ros2Error

PROBE_KINDS: dict[str, Kind] = {}
PROBES: dict[str, Probe] = {}
# Inputs a kind draws in its own code (not from ranges in the data), in words for teachers.
PROBE_DRAWS: dict[str, str] = {}
for _module in (core, perception, behaviour, tf):
    if set(_module.KINDS) != set(_module.PROBES) or set(_module.KINDS) & set(PROBE_KINDS):
        raise RuntimeError(f"{_module.__name__}: probe kinds without code, or defined twice")
    PROBE_KINDS.update(_module.KINDS)
    PROBES.update(_module.PROBES)
    PROBE_DRAWS.update(getattr(_module, "DRAWS", {}))

__all__ = ["PROBES", "PROBE_DRAWS", "PROBE_KINDS", "ProbeContext", "run_probe"]


def run_probe(ctx: ProbeContext, probe: Spec) -> Result:
    """One probe; any error becomes a failed result with its message."""
    try:
        return PROBES[probe.kind](ctx, probe)
    except (Ros2Error, ValueError, KeyError, TypeError, AttributeError) as exc:
        return Result(probe.kind, False, f"{type(exc).__name__}: {exc}")
