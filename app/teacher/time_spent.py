"""Time a learner spent on each lesson and exercise, as the gradebook's "time spent" shows it.

What counts, in words a teacher can check: a second counts for a lesson
while it is the lesson the learner's dashboard is on, and for an exercise
while it is the exercise the dashboard is on (the one of that lesson the
learner opened, saved or checked last) and they opened, saved or checked it
within the last ``IDLE_AFTER_SEC``; either only while the learner did
something the dashboard sees (a step, a check's state, their code, the
nodes they run) within the last ``IDLE_AFTER_SEC``. The two overlap: time
on an exercise is time on its lesson too. A dashboard that is not running
counts nothing, and neither does a machine that slept (each count adds at
most ``MAX_STEP_SEC``), so it is a lower bound of the time spent in the
classroom, never a guess.

The dashboard's beacon counts (one thread owns a ``TimeSpent``) and keeps
the totals in a small JSON file beside the learner's progress, so a
restarted dashboard goes on from them; the HTTP report carries them to the
hub. Pure: no ROS, no web server.
"""

from __future__ import annotations

import json
import logging
import os
import re
import tempfile
from collections.abc import Iterable, Mapping
from pathlib import Path

log = logging.getLogger(__name__)

IDLE_AFTER_SEC = 300.0  # five minutes without anything the dashboard sees: not counted
MAX_STEP_SEC = 5.0  # one count at most (the beacon counts once a second)
SAVE_EVERY_SEC = 30.0  # a dashboard killed at once loses at most this much
MAX_ACTIVITIES = 200  # the course has about 60 lessons and exercises
MAX_SECONDS = 2**31 - 1
KEY = re.compile(r"(lesson|exercise):[A-Za-z0-9_-]{1,64}")


def activity_key(kind: str, slug: str) -> str:
    """'lesson:05_topics', 'exercise:wall_stop': how the totals name an activity."""
    return f"{kind}:{slug}"


def valid_totals(totals: Mapping[str, int]) -> dict[str, int]:
    """Only well-named activities with a plausible number of seconds."""
    return {
        key: int(seconds)
        for key, seconds in list(totals.items())[:MAX_ACTIVITIES]
        if isinstance(key, str)
        and KEY.fullmatch(key)
        and isinstance(seconds, int)
        and not isinstance(seconds, bool)
        and 0 <= seconds <= MAX_SECONDS
    }


def read_totals(path: Path) -> dict[str, int]:
    """A totals file; {} when there is none or it cannot be read."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        return valid_totals(data["seconds"])
    except FileNotFoundError:
        return {}
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
        log.warning("%s is unreadable (%s): time spent starts from zero", path, exc)
        return {}


class TimeSpent:
    """The seconds counted per activity, kept in ``path`` (None: in memory only)."""

    def __init__(
        self,
        path: Path | None,
        idle_after: float = IDLE_AFTER_SEC,
        max_step: float = MAX_STEP_SEC,
    ) -> None:
        self.path = path
        self.idle_after, self.max_step = idle_after, max_step
        self._seconds: dict[str, float] = dict(read_totals(path)) if path else {}
        self._last_tick: float | None = None
        self._saved_at: float | None = None

    def tick(self, now: float, last_activity: float, current: Iterable[str]) -> None:
        """Count the time since the previous tick for each ``current`` activity, if the
        learner did something within ``idle_after`` seconds."""
        step = 0.0 if self._last_tick is None else now - self._last_tick
        self._last_tick = now
        if not 0 < step or now - last_activity > self.idle_after:
            return
        step = min(step, self.max_step)
        for key in current:
            if KEY.fullmatch(key) and (key in self._seconds or len(self._seconds) < MAX_ACTIVITIES):
                self._seconds[key] = self._seconds.get(key, 0.0) + step
        if self._saved_at is None:
            self._saved_at = now
        elif now - self._saved_at >= SAVE_EVERY_SEC:
            self.save()
            self._saved_at = now

    def totals(self) -> tuple[tuple[str, int], ...]:
        """Whole seconds per activity, sorted by name (what the report carries)."""
        return tuple(sorted((key, int(seconds)) for key, seconds in self._seconds.items()))

    def save(self) -> None:
        """Write the totals (atomically: a crash leaves the old file); never raises."""
        if self.path is None:
            return
        text = json.dumps({"version": 1, "seconds": dict(self.totals())})
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}-", dir=self.path.parent)
        except OSError as exc:  # counted on in memory; the next save tries again
            log.warning("could not keep the time spent in %s: %s", self.path, exc)
            return
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as out:
                out.write(text)
            os.replace(tmp, self.path)
        except OSError as exc:
            log.warning("could not keep the time spent in %s: %s", self.path, exc)
            Path(tmp).unlink(missing_ok=True)


def file_for(progress_file: Path) -> Path:
    """Where a learner's totals are kept: beside their progress file (``<learner>.json``)."""
    return progress_file.with_name(f"{progress_file.stem}.time.json")
