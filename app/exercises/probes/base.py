"""What every probe shares: the registry, its context, the author's formulas, comparisons.

Every probe is bounded in time and runs on the grader's worker thread (never
the executor thread): calls go through ``app.ros.calls``. A probe's result
says what was tried and what came back, e.g. "/multiply answered sum=8 for
a=3, b=5; expected 15".

Probe kinds register here as check kinds do in ``app.lessons.registry`` (one
family, one name space): ``@register_probe(name, required=..., optional=...,
words=...)`` on ``def run(ctx, probe) -> Result`` in a module of their own.
"""

from __future__ import annotations

import math
import random
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

from app.exercises.report import Result
from app.lessons.registry import CHECKS, Kind, add_kind, make_kind
from app.lessons.schema import Spec
from app.ros.context import CallContext

if TYPE_CHECKING:
    from collections.abc import Mapping
    from typing import TypeGuard

_V = TypeVar("_V")  # the values of a table, kept as they are

# Names an ``expect`` expression may use besides the request's own fields.
_SAFE_FUNCTIONS = {
    "abs": abs,
    "min": min,
    "max": max,
    "round": round,
    "sum": sum,
    "len": len,
    "range": range,
    "list": list,
}


class Programs(Protocol):
    """The processes of a grading, for probes that run the learner's program themselves."""

    def restart_learner(self, args: Sequence[str]) -> None:
        """Start the learner's program anew, with these command-line arguments."""

    def learner_alive(self) -> bool: ...

    def learner_output(self) -> list[str]:
        """What the learner's program printed since it last started."""

    def stop_setup(self) -> None:
        """Stop the exercise's setup nodes (and wait until they are gone)."""

    def start_setup(self) -> None: ...

    def setup_output(self) -> dict[str, list[str]]:
        """What each setup node printed since it last started, by catalog name."""


@dataclass
class ProbeContext:
    """What a probe works with: a node to call through, and the lessons' checks."""

    call: CallContext
    learner_node: str
    # Evaluates a lesson check until it passes or ``timeout`` runs out.
    wait_check: Callable[[Spec, float], tuple[bool, str]]
    rng: random.Random
    seed: int = 0  # what ``rng`` was seeded with: shown with the result, to replay a grading
    programs: Programs | None = None  # None where no program may be restarted
    # The statement's example (exercise data): a probe may avoid drawing it as the input.
    example: dict[str, Any] = field(default_factory=dict)


def expected_value(expression: str, names: Mapping[str, object]) -> Any:
    """Evaluate an exercise author's formula ("a * b") on the request's fields.

    The names are globals, so a comprehension in the formula sees them too
    ("[sum(values[: i + 1]) for i in range(len(values))]").
    """
    return eval(expression, {"__builtins__": {}, **_SAFE_FUNCTIONS, **names})


def is_range(value: object) -> TypeGuard[list[int | float]]:
    """``[low, high]`` of two numbers: a range to draw from (exercise data)."""
    return (
        isinstance(value, list)
        and len(value) == 2
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    )


def is_choice(value: object) -> TypeGuard[list[str]]:
    """A list of two or more words: one is drawn at grading time (exercise data)."""
    return isinstance(value, list) and len(value) >= 2 and all(isinstance(v, str) for v in value)


def is_drawn(value: object) -> bool:
    return is_range(value) or is_choice(value)


def draw(rng: random.Random, value: object) -> Any:
    """A value drawn at grading time: ``[low, high]`` ints or floats, one of a list of
    words; a table draws each of its fields; anything else as is."""
    if isinstance(value, dict):
        return {key: draw(rng, inner) for key, inner in value.items()}
    if is_choice(value):
        return rng.choice(value)
    if not is_range(value):
        return value
    low, high = value
    if isinstance(low, int) and isinstance(high, int):
        return rng.randint(low, high)
    return round(rng.uniform(float(low), float(high)), 3)


def range_text(value: object) -> str:
    """How a teacher reads a drawn field: "random in [-50, 50]", or the fixed value."""
    if is_choice(value):
        return "random, one of " + ", ".join(repr(v) for v in value)
    return f"random in [{value[0]}, {value[1]}]" if is_range(value) else repr(value)


def fill_template(text: str, names: Mapping[str, object]) -> str:
    """``"{a} + {b} = {a + b}"`` with each braced formula evaluated on ``names``."""
    return re.sub(r"\{([^{}]+)\}", lambda m: str(expected_value(m.group(1), names)), text)


def values_text(values: Mapping[str, object]) -> str:
    return ", ".join(f"{k}={v!r}" for k, v in values.items())


def random_inputs(rng: random.Random, ranges: Mapping[str, object]) -> dict[str, object]:
    return {name: draw(rng, value) for name, value in ranges.items()}


def same(actual: object, expected: object, tolerance: float) -> bool:
    """Equal, numbers within ``tolerance``; nested dicts and lists (messages) compared deeply."""
    if isinstance(actual, dict) and isinstance(expected, dict):
        return all(k in actual and same(actual[k], v, tolerance) for k, v in expected.items())
    if isinstance(actual, (list, tuple)) and isinstance(expected, (list, tuple)):
        return len(actual) == len(expected) and all(
            same(a, b, tolerance) for a, b in zip(actual, expected, strict=True)
        )
    if isinstance(actual, (int, float)) and isinstance(expected, (int, float)):
        return math.isclose(actual, expected, rel_tol=tolerance, abs_tol=tolerance)
    return bool(actual == expected)


def without_kind(table: Mapping[str, _V]) -> dict[str, _V]:
    return {k: v for k, v in table.items() if k != "kind"}


Probe = Callable[[ProbeContext, Spec], Result]


@dataclass(frozen=True)
class ProbeKind:
    """One probe kind: its fields, its code, and its words for the learner and the teacher."""

    name: str
    fields: Kind
    run: Probe
    words: str  # what it judges ("calls the service with random requests ...")
    draws: str = ""  # what it draws at grading time, in words (`exercise explain` shows it)
    # Fields an exercise may leave out, with their values: the ranges inputs are drawn
    # from live here, so the exercise file can change them and explain shows them.
    defaults: dict[str, object] = field(default_factory=dict)
    # It gives the node input (a request, messages, a parameter, a goal...); a kind that
    # only watches (a rate, QoS, a message on a topic) draws nothing.
    feeds: bool = True


PROBES: dict[str, ProbeKind] = {}


def register_probe(
    name: str,
    *,
    required: str,
    optional: str = "",
    words: str,
    draws: str = "",
    defaults: Mapping[str, object] | None = None,
    feeds: bool = True,
) -> Callable[[Probe], Probe]:
    """Decorator: ``run(ctx, probe) -> Result`` is the probe kind ``name``.

    ``defaults`` are optional fields with their values (the loader fills them in).
    """

    def add(run: Probe) -> Probe:
        if name in CHECKS:
            raise RuntimeError(f"probe kind '{name}' is already a check kind")
        fields = make_kind(required, " ".join([optional, *(defaults or {})]))
        kind = ProbeKind(name, fields, run, words, draws, dict(defaults or {}), feeds)
        add_kind(PROBES, "probe", name, kind)
        return run

    return add
