"""The time each LMS learner spent on each activity, for the gradebook's "time spent".

A learner's dashboard counts it (app/teacher/time_spent.py says what counts)
and sends its totals in every progress report; this keeps the newest per
learner and activity, on disk beside the outbox, so the gradebook still
shows it once the learner's server stopped or the service restarted. A total
never goes down here: a dashboard that lost its own file starts again from
zero, and the gradebook keeps the larger number it had.

Pure data and one JSON file; app/lti/pages.py shows it.
"""

from __future__ import annotations

import json
import logging
import re
import threading
import time
from collections.abc import Iterable
from pathlib import Path

from app.lti.state_file import save_json

log = logging.getLogger(__name__)

TIME_FILE = "time_spent.json"  # in the tool's folder
SAVE_EVERY_SEC = 60.0  # reports come every few seconds per learner: the file, at most this often
_NAME = re.compile(r"[A-Za-z0-9_-]{1,64}")  # a hub user's name, lti-...
_KEY = re.compile(r"(lesson|exercise):[A-Za-z0-9_-]{1,64}")
MAX_ACTIVITIES = 200  # per learner


class TimeBook:
    """Seconds per learner and activity ("lesson:05_topics", "exercise:wall_stop")."""

    def __init__(self, folder: Path, save_every: float = SAVE_EVERY_SEC) -> None:
        self.path = folder / TIME_FILE
        self.save_every = save_every
        self._lock = threading.Lock()
        self._writing = threading.Lock()  # one draft file: one writer at a time
        self._seconds: dict[str, dict[str, int]] = self._load()
        self._dirty = False
        self._saved_at = 0.0

    def update(
        self, learner: str, totals: Iterable[tuple[str, int]], now: float | None = None
    ) -> None:
        """A report's totals: each activity's larger number is kept."""
        if not _NAME.fullmatch(learner):
            return
        now = time.time() if now is None else now
        with self._lock:
            held = self._seconds.setdefault(learner, {})
            for key, seconds in totals:
                if not _KEY.fullmatch(key) or seconds <= held.get(key, -1):
                    continue
                if key in held or len(held) < MAX_ACTIVITIES:
                    held[key] = int(seconds)
                    self._dirty = True
            due = self._dirty and now - self._saved_at >= self.save_every
        if due:
            self.save(now)

    def of(self, learner: str, kind: str, slug: str) -> int | None:
        """The seconds counted for ``learner`` on an activity; None when none was reported."""
        with self._lock:
            return self._seconds.get(learner, {}).get(f"{kind}:{slug}")

    def save(self, now: float | None = None) -> None:
        """Write what changed since the last save (never raises)."""
        with self._lock:
            if not self._dirty:
                return
            data = {"version": 1, "seconds": {k: dict(v) for k, v in self._seconds.items()}}
            self._dirty = False
            self._saved_at = time.time() if now is None else now
        try:
            with self._writing:
                self.path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
                save_json(self.path, data)
        except OSError as exc:  # kept in memory; the next report tries again
            log.warning("LTI: could not keep the time spent in %s: %s", self.path, exc)
            with self._lock:
                self._dirty = True

    def _load(self) -> dict[str, dict[str, int]]:
        try:
            data = json.loads(self.path.read_text(encoding="utf-8"))
            return {
                learner: {
                    key: int(seconds)
                    for key, seconds in totals.items()
                    if _KEY.fullmatch(key) and isinstance(seconds, int) and seconds >= 0
                }
                for learner, totals in data["seconds"].items()
                if _NAME.fullmatch(learner)
            }
        except FileNotFoundError:
            return {}
        except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
            log.warning("LTI: %s is unreadable (%s); time spent starts afresh", self.path, exc)
            return {}
