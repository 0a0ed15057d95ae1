"""The graded attempts a learner's dashboard kept, read back as ``GradedAttempt``\\ s.

Each grading leaves a folder ``<attempts>/<exercise>/<UTC time>-seed<N>-<verdict>``
(app/exercises/attempts.py) whose ``metadata.yaml`` holds the grader's summary
and each result line. Two readers need them as plain data: the dashboard's
beacon, which sends the newest of the current exercise in its HTTP report (a
hub's teacher service cannot reach the learner's files), and the classroom
command's gradebook, which runs on the machine that holds every seat's folder.

Reading never raises: a folder that is still being recorded is skipped, and
one whose metadata cannot be read keeps what its name says.
"""

from __future__ import annotations

import calendar
import json
import logging
import re
import time
from pathlib import Path

import yaml

from app.teacher.record import MAX_FAILED, MAX_HISTORY, MAX_REASON, MAX_SUMMARY, GradedAttempt, clip

log = logging.getLogger(__name__)

# As app/exercises/attempts.py names and fills them (that module needs rclpy: not imported).
ATTEMPTS_FOLDER = "attempts"
UNFINISHED = ".recording"
CUSTOM_PREFIX = "classroom."
_NAME = re.compile(r"(\d{8}-\d{6})(?:-\d+)?(?:-seed(\d+))?-(pass|fail|problem)")


def attempt_from_folder(path: Path) -> GradedAttempt | None:
    """One kept attempt; None for a folder that is no finished attempt."""
    found = _NAME.fullmatch(path.name)
    if found is None:
        return None
    stamp, seed, verdict = found.groups()
    at = float(calendar.timegm(time.strptime(stamp, "%Y%m%d-%H%M%S")))
    attempt = GradedAttempt(at=at, verdict=verdict, seed=int(seed or 0))
    try:
        meta = yaml.safe_load((path / "metadata.yaml").read_text(encoding="utf-8"))
        custom = meta["rosbag2_bagfile_information"].get("custom_data") or {}
        results = json.loads(custom.get(CUSTOM_PREFIX + "results", "[]"))
        summary = str(custom.get(CUSTOM_PREFIX + "summary", ""))
        failed = [
            f"{r.get('name', '')}: {' '.join(str(r.get('detail', '')).split())}"
            for r in results
            if not r.get("passed")
        ]
        passed = sum(bool(r.get("passed")) for r in results)
    except (OSError, ValueError, KeyError, TypeError, AttributeError, yaml.YAMLError):
        return attempt  # a damaged bag: what its name says
    return GradedAttempt(
        at=at,
        verdict=verdict,
        seed=int(seed or 0),
        passed=passed,
        total=len(results),
        failed=tuple(clip(line, MAX_REASON) for line in failed[:MAX_FAILED]),
        summary=clip(" ".join(summary.split()), MAX_SUMMARY),
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
                key=lambda p: p.name,
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
