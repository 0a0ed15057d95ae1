"""The one registry of what a lesson may ask: step action kinds and check kinds.

Each kind has one home, a small module that registers itself: its fields
(the schema checks lesson and exercise files against them), its code, and
its words for the learner (what it means, shown by `exercise explain` and in
the lessons). Exercise probes are the third kind family: they build on the
checks (a probe may wait on any check kind), register the same way with
``register_probe`` in ``app.exercises.probes.base`` (one module per kind in
``app/exercises/probes/``), and share one name space with the checks.

To add a check kind, add one module, ``app/lessons/checks/<kind>.py``::

    from __future__ import annotations

    from typing import TYPE_CHECKING

    from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

    if TYPE_CHECKING:
        from app.lessons.runtime import LessonRuntime
        from app.lessons.schema import Spec


    @register_check("topic_quiet", required="topic", optional="seconds",
                    words="nothing is published on the topic")
    def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
        ...  # never block: return WAITING and look again at the next call

An action kind is the same in ``app/lessons/actions/<kind>.py`` with
``register_action`` and ``def perform(rt, action) -> str`` (the line the page
shows; it may block briefly, it runs on a job thread). Nothing else is
edited: each package imports all its modules, ``app.lessons.kinds`` lists
what registered, the schema validates against it and ``LessonRuntime``
dispatches to it. What a kind needs from the live system (graph snapshot,
topic taps, service poller, supervisor) it takes from the runtime ``rt``.
A kind registered twice is an error at import.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeVar

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

PASS, FAIL, WAITING = "pass", "fail", "waiting"


@dataclass(frozen=True)
class Kind:
    """The fields of one kind: those a file must give, and those it may."""

    required: frozenset[str]
    optional: frozenset[str] = frozenset()


def make_kind(required: str, optional: str = "") -> Kind:
    return Kind(frozenset(required.split()), frozenset(optional.split()))


@dataclass(frozen=True)
class CheckResult:
    state: str  # pass | fail | waiting
    reason: str = ""


@dataclass(frozen=True)
class CheckKind:
    name: str
    fields: Kind
    evaluate: Callable[[LessonRuntime, Spec], CheckResult]
    words: str  # what it means, for the learner and the teacher


@dataclass(frozen=True)
class ActionKind:
    name: str
    fields: Kind
    perform: Callable[[LessonRuntime, Spec], str]
    words: str


CHECKS: dict[str, CheckKind] = {}
ACTIONS: dict[str, ActionKind] = {}
Evaluate = TypeVar("Evaluate", bound="Callable[[LessonRuntime, Spec], CheckResult]")
Perform = TypeVar("Perform", bound="Callable[[LessonRuntime, Spec], str]")
E = TypeVar("E")


def add_kind(table: dict[str, E], family: str, name: str, entry: E) -> None:
    """Register ``entry`` as the kind ``name`` of a family; a name registered twice is an error."""
    if name in table:
        raise RuntimeError(f"{family} kind '{name}' registered twice")
    table[name] = entry


def register_check(
    name: str, *, required: str, optional: str = "", words: str
) -> Callable[[Evaluate], Evaluate]:
    """Decorator: ``evaluate(rt, check) -> CheckResult`` is the check kind ``name``."""

    def add(evaluate: Evaluate) -> Evaluate:
        add_kind(
            CHECKS, "check", name, CheckKind(name, make_kind(required, optional), evaluate, words)
        )
        return evaluate

    return add


def register_action(
    name: str, *, required: str, optional: str = "", words: str
) -> Callable[[Perform], Perform]:
    """Decorator: ``perform(rt, action) -> str`` is the step action kind ``name``."""

    def add(perform: Perform) -> Perform:
        add_kind(
            ACTIONS, "action", name, ActionKind(name, make_kind(required, optional), perform, words)
        )
        return perform

    return add


def import_all(package: str, path: list[str]) -> None:
    """Import every module of a kinds package, so each registers itself."""
    for module in pkgutil.iter_modules(path):
        if not module.name.startswith("_"):
            importlib.import_module(f"{package}.{module.name}")
