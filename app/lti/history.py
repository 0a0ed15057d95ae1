"""What the gradebook knows of a learner's graded attempts at an exercise, and where from.

A cell of the class grid opens one learner's history of one activity: each
grading with its time, verdict, checks passed, the failed checks with their
short reasons, and the seed that replays it. Where those come from depends
on the deployment, so the page takes them as plain ``Attempt`` values with a
sentence on where they were read (``AttemptSource``):

- on a JupyterHub, learners' servers are out of the teacher service's reach;
  each dashboard's progress report carries the newest attempts of the
  exercise it is on, and ``AttemptHistory`` keeps them here, per learner, on
  disk beside the outbox (so an exercise the learner left, a learner whose
  server is stopped, and a restarted service still show them);
- in the classroom mode, every seat's dashboard keeps its attempts on the
  classroom's own machine, which reads them where they are.

Pure data and one JSON file per learner; app/lti/pages.py draws them.
"""

from __future__ import annotations

import json
import logging
import re
import threading
from collections.abc import Iterable
from dataclasses import asdict, dataclass
from pathlib import Path

from app.lti.state_file import save_json

log = logging.getLogger(__name__)

HISTORY_FOLDER = "attempts"  # in the tool's folder: <learner>.json
KEEP_PER_EXERCISE = 20  # twice what a dashboard keeps: the hub also remembers pruned ones
_NAME = re.compile(r"[A-Za-z0-9_-]{1,64}")  # a hub user's name, lti-...
_SLUG = re.compile(r"[a-z][a-z0-9_]{2,48}")  # an exercise's


@dataclass(frozen=True)
class Attempt:
    """One grading, as the gradebook shows it (the fields of app.teacher's GradedAttempt)."""

    at: float  # wall-clock seconds
    verdict: str  # "pass", "fail" or "problem" (not graded)
    seed: int = 0  # 0: none kept
    passed: int = 0
    total: int = 0
    failed: tuple[str, ...] = ()  # "check: why", short
    summary: str = ""
    graded_file: str = ""  # the code it graded, kept on the dashboard's machine ('' : not kept)

    @property
    def key(self) -> tuple[float, str, int]:
        return (self.at, self.verdict, self.seed)


@dataclass(frozen=True)
class AttemptSource:
    """The attempts of one learner at one exercise, and what the teacher should know of them."""

    attempts: tuple[Attempt, ...]  # newest first
    where: str  # where they were read, in a sentence
    replay: str  # why this page has no replay button (the clause after "no replay button here:")
    code_file: str = ""  # the learner's code for the replay command ('' : not known here)
    recordings: str = ""  # where the recorded attempts (MCAP) are, and how to watch one


def valid_names(learner: str, slug: str) -> bool:
    """A learner's and an exercise's name that may become part of a path."""
    return bool(_NAME.fullmatch(learner) and _SLUG.fullmatch(slug))


class AttemptHistory:
    """The graded attempts the hub's progress reports brought, per learner and exercise."""

    def __init__(self, folder: Path, keep: int = KEEP_PER_EXERCISE) -> None:
        self.folder = folder / HISTORY_FOLDER
        self.keep = keep
        self._lock = threading.Lock()
        self._cache: dict[str, dict[str, list[Attempt]]] = {}

    def add(self, learner: str, slug: str, attempts: Iterable[Attempt]) -> int:
        """Keep the attempts not seen before (the newest ``keep``); how many were new."""
        if not valid_names(learner, slug):
            return 0
        with self._lock:
            book = self._load(learner)
            held = book.get(slug, [])
            known = {a.key for a in held}
            new = [a for a in attempts if a.key not in known]
            if not new:
                return 0
            merged = sorted([*held, *new], key=lambda a: a.at, reverse=True)[: self.keep]
            book[slug] = merged
            try:
                self.folder.mkdir(parents=True, exist_ok=True, mode=0o700)
                save_json(
                    self.folder / f"{learner}.json",
                    {
                        "version": 1,
                        "exercises": {s: [asdict(a) for a in kept] for s, kept in book.items()},
                    },
                )
            except OSError as exc:  # the page shows what is in memory; the next report retries
                log.warning("LTI: could not keep %s's attempts: %s", learner, exc)
            return len(new)

    def of(self, learner: str, slug: str) -> tuple[Attempt, ...]:
        """The kept attempts, newest first."""
        if not valid_names(learner, slug):
            return ()
        with self._lock:
            return tuple(self._load(learner).get(slug, ()))

    def _load(self, learner: str) -> dict[str, list[Attempt]]:
        book = self._cache.get(learner)
        if book is not None:
            return book
        book = {}
        path = self.folder / f"{learner}.json"
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
            for slug, kept in data["exercises"].items():
                book[slug] = [
                    Attempt(**{**item, "failed": tuple(item.get("failed", ()))}) for item in kept
                ]
        except FileNotFoundError:
            pass
        except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
            log.warning("LTI: %s is unreadable (%s); starting %s's history afresh", path, exc,
                        learner)  # fmt: skip
            book = {}
        self._cache[learner] = book
        return book
