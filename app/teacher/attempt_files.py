"""The graded attempts a learner's dashboard kept, read back as ``GradedAttempt``\\ s.

Each grading leaves a folder ``<attempts>/<exercise>/<UTC time>-seed<N>-<verdict>``
whose ``metadata.yaml`` holds the grader's summary and each result line
(named and read by app/exercises/attempt_folders.py, which needs no ROS).
Two readers need them as plain data: the dashboard's beacon, which sends the
newest of the current exercise in its HTTP report (a hub's teacher service
cannot reach the learner's files), and the classroom command's gradebook,
which runs on the machine that holds every seat's folder.

The classroom's teacher page also lists a learner's kept attempts
(``kept_attempts``), says what one of them judged (``attempt_markdown``) and
finds its plots (``plot_files``), as the learner's own Exercise tab does.

Reading never raises: a folder that is still being recorded is skipped (the
teacher's list shows it as damaged), and one whose metadata cannot be read
keeps what its name says.
"""

from __future__ import annotations

import logging
import re
import time
from pathlib import Path

from app.exercises.attempt_folders import (
    ATTEMPTS_FOLDER,
    UNFINISHED,
    age_order,
    attempt_label,
    graded_code,
    parse_name,
    read_verdict,
    replay_of,
)
from app.teacher.record import (
    MAX_FAILED,
    MAX_GRADED_FILE,
    MAX_HISTORY,
    MAX_REASON,
    MAX_SUMMARY,
    GradedAttempt,
    clip,
    plain_markdown,
)

log = logging.getLogger(__name__)

MOST_PLOTS = 4  # plots shown of one attempt (a grading draws one a judged quantity)
GRADING_NOW_SEC = 30.0  # an unfinished folder written to this recently is a grading under way
MAX_PLOT_BYTES = 4 * 1024 * 1024  # a plot is ~50 kB; anything larger is not ours
_PLOT = re.compile(r"plot-(\d{1,3})-[^/]*\.png")


def attempt_from_folder(path: Path) -> GradedAttempt | None:
    """One kept attempt; None for a folder that is no finished attempt."""
    name = parse_name(path.name)
    if name is None:
        return None
    code = graded_code(path)
    attempt = GradedAttempt(
        at=name.at,
        verdict=name.verdict,
        seed=name.seed or 0,
        # A path cut short would name another file: a long one is left out.
        graded_file=str(code) if code and len(str(code)) <= MAX_GRADED_FILE else "",
    )
    kept = read_verdict(path)
    if kept is None:
        return attempt  # a damaged bag: what its name says
    failed = [f"{r.name}: {' '.join(r.detail.split())}" for r in kept.results if not r.passed]
    return GradedAttempt(
        at=attempt.at,
        verdict=attempt.verdict,
        seed=attempt.seed,
        passed=sum(r.passed for r in kept.results),
        total=len(kept.results),
        failed=tuple(clip(line, MAX_REASON) for line in failed[:MAX_FAILED]),
        summary=clip(" ".join(kept.summary.split()), MAX_SUMMARY),
        graded_file=attempt.graded_file,
    )


class AttemptReader:
    """Reads an exercise's attempt folder, each finished attempt once (their names never change)."""

    def __init__(self) -> None:
        self._seen: dict[Path, dict[str, GradedAttempt | None]] = {}  # by folder, by name

    def newest(self, folder: Path, limit: int = MAX_HISTORY) -> tuple[GradedAttempt, ...]:
        """The newest ``limit`` finished attempts in ``folder``, newest first."""
        try:
            names = sorted(
                (p for p in folder.iterdir() if not p.name.endswith(UNFINISHED)),
                key=lambda p: age_order(p.name),
                reverse=True,
            )
        except OSError:  # no attempt yet, or not readable
            return ()
        known = self._seen.get(folder, {})
        seen: dict[str, GradedAttempt | None] = {}  # the pruned ones drop out
        found: list[GradedAttempt] = []
        for path in names:
            if len(found) >= limit:
                break
            if path.name in known:
                seen[path.name] = known[path.name]
            else:
                seen[path.name] = attempt_from_folder(path) if path.is_dir() else None
            attempt = seen[path.name]
            if attempt is not None:
                found.append(attempt)
        self._seen[folder] = seen
        return tuple(found)


def exercise_folder(bags: Path, slug: str) -> Path:
    """Where a dashboard whose bags folder is ``bags`` keeps the attempts at ``slug``."""
    return bags / ATTEMPTS_FOLDER / slug


def kept_attempts(folder: Path) -> list[Path]:
    """Every kept attempt in an exercise's ``folder``, newest first, as the learner's own
    Attempt dropdown lists them (one still recording, or left so by a crash, included:
    its label says it is damaged); [] when there is none or it cannot be read."""
    try:
        return sorted(
            (p for p in folder.iterdir() if p.is_dir()),
            key=lambda p: age_order(p.name),
            reverse=True,
        )
    except OSError:
        return []


def plot_files(attempt: Path) -> list[Path]:
    """The attempt's plots (``plot-N-<title>.png``), in N's order, at most MOST_PLOTS; one too
    large to be a plot is left out."""
    try:
        found = [(int(m.group(1)), p) for p in attempt.iterdir() if (m := _PLOT.fullmatch(p.name))]
        plots = [p for _n, p in sorted(found) if p.is_file() and p.stat().st_size <= MAX_PLOT_BYTES]
    except OSError:
        return []
    return plots[:MOST_PLOTS]


def _written_within(folder: Path, seconds: float) -> bool:
    """Whether anything in ``folder`` was written in the last ``seconds``."""
    try:
        newest = max((p.stat().st_mtime for p in folder.iterdir()), default=0.0)
    except OSError:
        return False
    return time.time() - newest < seconds


def _code(text: str) -> str:
    """Inline code whose backtick fence is longer than any run of backticks inside it."""
    fence = "`" * (max((len(run) for run in re.findall(r"`+", text)), default=0) + 1)
    return f"{fence} {text} {fence}" if "`" in text else f"`{text}`"


def attempt_markdown(attempt: Path) -> str:
    """What a teacher reads of one kept attempt: when and how it ended, each result line as
    the learner saw it (the failed ones marked ✗), where its recording is and the command
    that grades its code again. A damaged attempt says so; this never raises."""
    try:
        label = attempt_label(attempt)
        kept = read_verdict(attempt)
        mcap = sorted(attempt.glob("*.mcap"))
        command = replay_of(attempt)
    except (OSError, ValueError) as exc:  # a folder gone under us, a name that is no name
        return f"⚠ This attempt cannot be read: {plain_markdown(str(exc))}"
    parts = [f"**{plain_markdown(label)}**"]
    if kept is not None:
        # The result lines hold what the learner's node said: shown, never interpreted.
        if kept.summary:
            parts.append(f"**{plain_markdown(kept.summary)}**")
        parts.append(
            "\n".join(
                f"- {'✓' if r.passed else '✗'} **{plain_markdown(r.name)}**: "
                f"{plain_markdown(r.detail)}"
                for r in kept.results
            )
        )
    elif attempt.name.endswith(UNFINISHED) and _written_within(attempt, GRADING_NOW_SEC):
        parts.append(
            "⏳ **Being graded now**: its recording is still being written. Its verdict "
            "shows here when the grading ends."
        )
    else:
        parts.append(
            "⚠ **Damaged**: its verdict cannot be read (the grading was cut short, or the "
            "file is truncated). **Watch this attempt** plays what can be read."
        )
    where = _code(str(mcap[0])) if mcap else _code(str(attempt))
    parts.append(f"Recording: {where} (Foxglove or Lichtblick open it: Open local file)")
    if command:
        parts.append(f"Its grading again, on the code it graded: {_code(command)}")
    return "\n\n".join(part for part in parts if part)
