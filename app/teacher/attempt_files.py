"""The graded attempts a learner's dashboard kept, read back as ``GradedAttempt``\\ s.

Each grading leaves a folder ``<attempts>/<exercise>/<UTC time>-seed<N>-<verdict>``
whose ``metadata.yaml`` holds the grader's summary and each result line
(named and read by app/exercises/attempt_folders.py, which needs no ROS).
Two readers need them as plain data: the dashboard's beacon, which sends the
newest of the current exercise in its HTTP report (a hub's teacher service
cannot reach the learner's files), and the classroom command's gradebook,
which runs on the machine that holds every seat's folder.

Reading never raises: a folder that is still being recorded is skipped, and
one whose metadata cannot be read keeps what its name says.
"""

from __future__ import annotations

import logging
from pathlib import Path

from app.exercises.attempt_folders import (
    ATTEMPTS_FOLDER,
    UNFINISHED,
    age_order,
    graded_code,
    parse_name,
    read_verdict,
)
from app.teacher.record import (
    MAX_FAILED,
    MAX_GRADED_FILE,
    MAX_HISTORY,
    MAX_REASON,
    MAX_SUMMARY,
    GradedAttempt,
    clip,
)

log = logging.getLogger(__name__)


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
