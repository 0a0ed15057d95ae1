"""One learner's progress as plain data, the "stuck" rule, the class table and its exercises.

Everything here is pure: the dashboard fills a ``LearnerRecord``, the wire
module turns it into a message and back, and the teacher page, the CSV
export and ``classroom status`` all render the same ``table`` rows; both
teacher pages (``classroom``'s and the hub's) show the same
``class_exercises`` lines.
"""

from __future__ import annotations

import csv
import io
import re
import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, fields

# Bounds of the message (interfaces/classroom_interfaces/msg/LearnerProgress.msg).
MAX_NAME = 64
MAX_TITLE = 120
MAX_CHECKS = 16
MAX_REASON = 160
MAX_CODE = 4000
MAX_ERROR = 1000
MAX_NODES = 32
MAX_NOTICE = 280
MAX_MISTAKE = 120
MAX_HISTORY = 10  # graded attempts of the current exercise in a report (the dashboard keeps 10)
MAX_FAILED = 8  # failed checks told per attempt
MAX_SUMMARY = 300
MAX_GRADED_FILE = 300  # the path of an attempt's kept code (longer ones are not sent)

_MARKS = {"pass": "✓", "fail": "✗", "waiting": "…"}


def clip(text: str, limit: int) -> str:
    """At most ``limit`` characters; a cut string ends in an ellipsis."""
    return text if len(text) <= limit else text[: limit - 1] + "…"


_MARKDOWN_SPECIAL = re.compile(r"([\\`*_{}\[\]()<>#+!|~])")


def plain_markdown(text: str) -> str:
    """Text shown as itself on a page: no links, images, HTML or emphasis from it.

    Anyone on the classroom domain can publish (DDS has no sender check here),
    so what arrives over it is shown, never interpreted.
    """
    return _MARKDOWN_SPECIAL.sub(r"\\\1", " ".join(text.split()))


@dataclass(frozen=True)
class GradedAttempt:
    """One grading of an exercise, as the learner's dashboard kept it (its attempt folder).

    What the teacher's gradebook shows of it: when, the verdict, how many checks
    passed, each failed check with the short reason it gave, and the seed its
    hidden inputs came from (``exercise check SLUG FILE --seed N`` replays it).
    """

    at: float  # when the grading ran (wall-clock seconds, UTC)
    verdict: str  # "pass", "fail", or "problem" (not graded: the program did not run, ...)
    seed: int = 0  # 0: none kept
    passed: int = 0  # checks and probes passed ...
    total: int = 0  # ... of this many
    failed: tuple[str, ...] = ()  # "name: why", at most MAX_FAILED, each at most MAX_REASON
    summary: str = ""  # the grader's last line, at most MAX_SUMMARY ("3 of 5 checks passed: ...")
    # The code it graded, as kept in its folder, on the dashboard's machine: what the
    # replay command grades ('' : not kept, e.g. an attempt made before it was).
    graded_file: str = ""


VERDICTS = ("pass", "fail", "problem")


@dataclass(frozen=True)
class LearnerRecord:
    """What the teacher sees of one learner (immutable: safe to hand to any thread)."""

    site: str
    learner: str
    domain_id: int = 0
    lesson_id: str = ""
    unit: int = 0
    lesson_title: str = ""
    step: int = 0  # 1-based
    steps: int = 0
    step_title: str = ""
    steps_passed: int = 0
    check_states: tuple[str, ...] = ()
    check_reasons: tuple[str, ...] = ()
    exercises_passed: int = 0
    exercise_attempts: int = 0
    exercise: str = ""
    exercise_attempts_here: int = 0
    exercise_failed_here: int = 0
    exercise_passed_here: bool = False
    exercise_passed_seed: int = 0  # the passing grading's seed (0: none kept): replays it
    # What the last failed check of it matched: a recorded mistake's name
    # ("front_is_index_zero") or, when none matched, the failed result's name
    # ("stop before the wall"); '' when it passed or never failed.
    exercise_mistake: str = ""
    # Its newest graded attempts, newest first (at most MAX_HISTORY). Only the HTTP
    # report (a hub) carries them; on the classroom domain the teacher's side reads
    # them from the dashboards' folders on its own machine instead.
    exercise_history: tuple[GradedAttempt, ...] = ()
    # Seconds of active time per activity ("lesson:05_topics", "exercise:wall_stop"),
    # counted by the dashboard (app/teacher/time_spent.py). HTTP report only, like the
    # history; it grows every second, so it is no change by itself.
    time_spent: tuple[tuple[str, int], ...] = ()
    code_excerpt: str = ""
    last_error: str = ""
    nodes_running: tuple[str, ...] = ()
    last_activity: float = 0.0  # wall-clock seconds
    last_progress: float = 0.0
    received_at: float = field(default=0.0, compare=False)  # set by the teacher side

    @property
    def key(self) -> str:
        return f"{self.site}/{self.learner}"

    def what_changed_ignoring_stamps(self) -> tuple:
        """Everything a learner can change; equal tuples mean nothing happened."""
        skip = {"last_activity", "last_progress", "received_at", "time_spent"}
        return tuple(getattr(self, f.name) for f in fields(self) if f.name not in skip)

    def position(self) -> tuple:
        """Moving to another step, passing one or passing an exercise is progress."""
        return (self.lesson_id, self.step, self.steps_passed, self.exercises_passed)


@dataclass(frozen=True)
class StuckRule:
    """When the teacher page marks a learner stuck (both limits are the teacher's)."""

    no_progress_sec: float = 300.0  # ...with a failing check of the step
    failed_checks: int = 3  # ...of the same exercise, not yet passed

    def reason(self, record: LearnerRecord, now: float) -> str:
        """Why this learner looks stuck, or '' when they do not."""
        idle = now - record.last_progress
        if "fail" in record.check_states and idle >= self.no_progress_sec:
            return f"no progress for {_age(idle)} while a check fails"
        if (
            record.exercise
            and not record.exercise_passed_here
            and record.exercise_failed_here >= self.failed_checks
        ):
            return f"{record.exercise} failed {record.exercise_failed_here} times"
        return ""


def _age(seconds: float) -> str:
    seconds = max(0.0, seconds)
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def checks_text(record: LearnerRecord) -> str:
    """'✓✓✗ 2/3' (marks in the step's order, then passed of total)."""
    if not record.check_states:
        return "–"
    marks = "".join(_MARKS.get(state, "?") for state in record.check_states)
    passed = sum(state == "pass" for state in record.check_states)
    return f"{marks} {passed}/{len(record.check_states)}"


_STEM = re.compile(r"[a-z0-9]+(?:_[a-z0-9]+)*")


def mistake_words(mistake: str) -> str:
    """A mistake as a teacher reads it: a recorded mistake's name in plain words
    ("front is index zero"), a check no recorded mistake explains as failed
    ('"stop before the wall" failed'), '' for none."""
    if not mistake:
        return ""
    if _STEM.fullmatch(mistake):
        return mistake.replace("_", " ")
    return f"“{mistake}” failed"


def exercise_now(record: LearnerRecord) -> str:
    """'wall_stop ✗ front is index zero', 'wall_stop ✓', 'wall_stop' (not checked yet) or '–'."""
    if not record.exercise:
        return "–"
    if record.exercise_passed_here:
        return f"{record.exercise} ✓"
    if record.exercise_mistake:
        return f"{record.exercise} ✗ {mistake_words(record.exercise_mistake)}"
    if record.exercise_failed_here:
        return f"{record.exercise} ✗"
    return record.exercise


COLUMNS = (
    "learner", "where", "unit · step", "checks", "exercises", "exercise now", "nodes",
    "last activity", "stuck",
)  # fmt: skip
OFFLINE_AFTER_SEC = 30.0  # three missed heartbeats


def table(records: Iterable[LearnerRecord], rule: StuckRule, now: float | None = None) -> list:
    """The class table as rows of display strings (``COLUMNS``), sorted by learner."""
    now = time.time() if now is None else now
    rows = []
    for r in sorted(records, key=lambda r: (r.site, _natural(r.learner))):
        stuck = rule.reason(r, now)
        seen = now - r.received_at if r.received_at else 0.0
        activity = f"{_age(now - r.last_activity)} ago"
        if seen > OFFLINE_AFTER_SEC:
            activity += f" (offline {_age(seen)})"
        rows.append(
            (
                r.learner,
                f"{r.site} · domain {r.domain_id}",
                f"{r.unit} · {r.step}/{r.steps}" if r.steps else "–",
                checks_text(r),
                f"{r.exercises_passed} passed · {r.exercise_attempts} attempts",
                exercise_now(r),
                ", ".join(r.nodes_running) or "–",
                activity,
                f"⚠ {stuck}" if stuck else "",
            )
        )
    return rows


def _natural(name: str) -> tuple:
    """learner2 before learner10."""
    head = name.rstrip("0123456789")
    tail = name[len(head) :]
    return (head, int(tail) if tail else -1)


UNKNOWN_FAILURE = "failed, reason not known"  # a dashboard that sent no mistake


@dataclass(frozen=True)
class ExerciseTally:
    """Where the class stands on one exercise: who passed, who is on it, and why they fail."""

    exercise: str
    passed: tuple[str, ...]
    trying: tuple[str, ...]
    # (the mistake in plain words, the learners whose last check matched it), largest first
    failures: tuple[tuple[str, tuple[str, ...]], ...]

    def line(self) -> str:
        """'wall_stop: 3 passed, 4 trying — front is index zero: ana, ben; ...'"""
        head = f"{self.exercise}: {len(self.passed)} passed, {len(self.trying)} trying"
        groups = "; ".join(f"{words}: {', '.join(who)}" for words, who in self.failures)
        return f"{head} — {groups}" if groups else head


def tally_exercises(
    records: Iterable[LearnerRecord], names: Mapping[str, str] | None = None
) -> list[ExerciseTally]:
    """Each exercise someone is on (by its name), its learners by name (``names``: a
    learner's display name, e.g. the LMS's; a class over several sites adds the site)."""
    records = sorted(records, key=lambda r: (_natural(r.learner), r.site))
    names = names or {}
    several_sites = len({r.site for r in records}) > 1

    def who(r: LearnerRecord) -> str:
        shown = names.get(r.learner) or r.learner
        return f"{shown} ({r.site})" if several_sites else shown

    by_exercise: dict[str, list[LearnerRecord]] = {}
    for r in records:
        if r.exercise:
            by_exercise.setdefault(r.exercise, []).append(r)
    tallies = []
    for exercise in sorted(by_exercise):
        on_it = by_exercise[exercise]
        groups: dict[str, list[str]] = {}
        for r in on_it:
            if r.exercise_passed_here:
                continue
            if r.exercise_mistake:
                groups.setdefault(mistake_words(r.exercise_mistake), []).append(who(r))
            elif r.exercise_failed_here:
                groups.setdefault(UNKNOWN_FAILURE, []).append(who(r))
        ranked = sorted(groups.items(), key=lambda item: (-len(item[1]), item[0]))
        tallies.append(
            ExerciseTally(
                exercise,
                passed=tuple(who(r) for r in on_it if r.exercise_passed_here),
                trying=tuple(who(r) for r in on_it if not r.exercise_passed_here),
                failures=tuple((words, tuple(learners)) for words, learners in ranked),
            )
        )
    return tallies


def class_exercises(
    records: Iterable[LearnerRecord], names: Mapping[str, str] | None = None
) -> list[str]:
    """The "Exercises across the class" lines both teacher pages show, one per exercise."""
    return [tally.line() for tally in tally_exercises(records, names)]


def text_table(rows: list, columns: tuple[str, ...] = COLUMNS) -> str:
    """Fixed-width columns for a terminal."""
    widths = [max([len(c), *(len(str(row[i])) for row in rows)]) for i, c in enumerate(columns)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(columns, widths, strict=True)).rstrip()]
    lines.append("  ".join("-" * w for w in widths))
    lines += [
        "  ".join(str(v).ljust(w) for v, w in zip(row, widths, strict=True)).rstrip()
        for row in rows
    ]
    return "\n".join(lines)


CSV_FIELDS = (
    "site", "learner", "domain_id", "lesson_id", "unit", "lesson_title", "step", "steps",
    "step_title", "steps_passed", "checks", "exercises_passed", "exercise_attempts", "exercise",
    "exercise_attempts_here", "exercise_failed_here", "exercise_passed_here", "exercise_mistake",
    "nodes_running", "last_activity", "last_progress", "stuck",
)  # fmt: skip


def _iso(stamp: float) -> str:
    return time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(stamp)) if stamp else ""


def to_csv(records: Iterable[LearnerRecord], rule: StuckRule, now: float | None = None) -> str:
    """The class's progress for a spreadsheet: one row per learner, raw values."""
    now = time.time() if now is None else now
    out = io.StringIO()
    writer = csv.writer(out)
    writer.writerow(CSV_FIELDS)
    for r in sorted(records, key=lambda r: (r.site, _natural(r.learner))):
        writer.writerow(
            [
                r.site, r.learner, r.domain_id, r.lesson_id, r.unit, r.lesson_title, r.step,
                r.steps, r.step_title, r.steps_passed, " ".join(r.check_states),
                r.exercises_passed, r.exercise_attempts, r.exercise, r.exercise_attempts_here,
                r.exercise_failed_here, r.exercise_passed_here, r.exercise_mistake,
                ";".join(r.nodes_running),
                _iso(r.last_activity), _iso(r.last_progress), rule.reason(r, now),
            ]
        )  # fmt: skip
    return out.getvalue()
