"""What grading says: one line per check or probe, then the verdict."""

from __future__ import annotations

from dataclasses import dataclass, field

from app.exercises.trace import Trace

PASS, FAIL = "pass", "fail"


@dataclass(frozen=True)
class Result:
    """One check or probe: what was tried, and what came back."""

    name: str  # e.g. "service /multiply" or "node_running /counter"
    passed: bool
    detail: str
    traces: tuple[Trace, ...] = ()  # the quantities it judged over time, to plot

    def line(self) -> str:
        return f"{'PASS' if self.passed else 'FAIL'}  {self.name}: {self.detail}"


@dataclass
class Report:
    slug: str
    results: list[Result] = field(default_factory=list)
    problem: str = ""  # why grading could not even start (no process, syntax error, ...)
    seed: int | None = None  # the probes' inputs were drawn from it: replays the grading
    attempt: str = ""  # the bag this grading was recorded into (app/exercises/attempts.py)
    attempt_note: str = ""  # why it was not kept, when it was not
    plots: list[str] = field(default_factory=list)  # PNG files of the results' traces

    def traces(self) -> list[Trace]:
        return [trace for result in self.results for trace in result.traces]

    @property
    def passed(self) -> bool:
        return not self.problem and bool(self.results) and all(r.passed for r in self.results)

    def failures(self) -> list[Result]:
        return [r for r in self.results if not r.passed]

    def summary(self) -> str:
        if self.problem:
            return f"Not graded: {self.problem}"
        good = sum(r.passed for r in self.results)
        verdict = "passed" if self.passed else "not yet"
        replay = f" Inputs drawn with seed {self.seed}." if self.seed is not None else ""
        return f"{good} of {len(self.results)} checks passed: {verdict}.{replay}"
