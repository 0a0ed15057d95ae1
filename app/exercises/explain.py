"""How an exercise is graded, in words a teacher can check before a course.

Shows every check and probe with its fields; fields drawn at grading time
show their range ("random in [-50, 50]"), never a value, because the values
come from a seed picked when the grading runs (shown in its result). Built
from the exercise data alone, so a new probe kind is explained without code
here.
"""

from __future__ import annotations

from app.exercises.model import Exercise
from app.exercises.probes import PROBES
from app.exercises.probes.base import is_drawn, range_text
from app.lessons.kinds import CHECKS
from app.lessons.schema import Spec

HOW_INPUTS_ARE_DRAWN = (
    "Inputs marked 'random' are drawn anew at every grading from a seed printed with the "
    "result; `exercise check SLUG FILE --seed N` replays that grading exactly. The "
    "statement's example is never the tested input."
)


def _field_text(value: object) -> str:
    if is_drawn(value):
        return range_text(value)
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_field_text(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list) and len(value) > 4:
        return f"{len(value)} entries"
    return repr(value)


def spec_line(spec: Spec) -> str:
    """One check or probe: its kind, then each field (ranges shown as ranges)."""
    fields = ", ".join(f"{k} {_field_text(v)}" for k, v in spec.fields.items())
    return f"{spec.kind.replace('_', ' ')}: {fields}" if fields else spec.kind.replace("_", " ")


def drawn_fields(spec: Spec) -> list[str]:
    """The names of a probe's fields drawn at grading time (nested ones as a.b)."""
    found: list[str] = []

    def walk(value: object, path: str) -> None:
        if is_drawn(value):
            found.append(path)
        elif isinstance(value, dict):
            for key, inner in value.items():
                walk(inner, f"{path}.{key}" if path else key)

    walk(spec.fields, "")
    if "walk" in spec.fields:
        found = [f for f in found if f != "walk"] + ["the order of lifecycle requests"]
    if spec.kind in PROBES and PROBES[spec.kind].draws:
        found.append(PROBES[spec.kind].draws)
    return found


def explain(exercise: Exercise) -> list[str]:
    """Lines for `exercise explain SLUG`: what is checked, what is probed, which ranges."""
    lines = [f"{exercise.slug}: {exercise.title} (your node {exercise.node})"]
    if exercise.setup:
        lines.append(f"started first: {', '.join(exercise.setup)}")
    for check in exercise.checks:
        words = CHECKS[check.kind].words if check.kind in CHECKS else ""
        lines.append(f"check  {spec_line(check)}" + (f" ({words})" if words else ""))
    for probe in exercise.probes:
        kind = PROBES[probe.kind]
        lines.append(f"probe  {spec_line(probe)} ({kind.words})")
        if kind.draws:
            lines.append(f"       draws {kind.draws}")
    lines.append(HOW_INPUTS_ARE_DRAWN)
    return lines


def panel_line(exercise: Exercise) -> str:
    """One line for the exercise panel: what varies between gradings."""
    drawn = sorted({name for p in exercise.probes for name in drawn_fields(p)})
    if not drawn:
        return "Grading: fixed checks on the live graph (nothing is drawn at random)."
    return (
        f"Grading draws {', '.join(drawn)} at random each time (seed shown in the result); "
        f"`exercise explain {exercise.slug}` lists every check and range."
    )
