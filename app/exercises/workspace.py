"""A learner's exercise code on disk, saved so that nothing is ever lost.

Each save is atomic (temporary file, fsync, rename, fsync of the folder), so
a reload, a restart or a SIGKILL of the dashboard at any moment leaves the
previous or the new code, never half of it. The code lives beside the
learner's progress file; attempts and time go into that progress file.

A Run copies the code into the learner's scratch folder and runs the copy:
the scratch folder is the only place contained code may write, and the
progress folder stays out of its reach.
"""

from __future__ import annotations

import difflib
import os
import tempfile
import threading
import time
from pathlib import Path

from app.exercises.model import Exercise
from app.lessons.progress import Added, ProgressStore

MAX_CODE_CHARS = 200_000  # a node is a few hundred lines; this is a paste gone wrong


class CodeTooLong(ValueError):
    pass


def write_atomically(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}-", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    dir_fd = os.open(path.parent, os.O_RDONLY)
    try:
        os.fsync(dir_fd)
    finally:
        os.close(dir_fd)


class Workspace:
    """One learner's code for every exercise, and their attempts. Thread-safe."""

    def __init__(self, progress: ProgressStore, scratch_root: Path) -> None:
        self.progress = progress
        learner = progress.path.stem
        self.code_dir = progress.path.parent / f"{learner}.code"
        self.scratch_root = scratch_root
        self.scratch = scratch_root / learner
        self._lock = threading.Lock()

    def _path(self, exercise: Exercise) -> Path:
        return self.code_dir / f"{exercise.slug}.py"

    def code(self, exercise: Exercise) -> str:
        """The learner's latest code, or the starter if they have not typed yet."""
        with self._lock:
            try:
                return self._path(exercise).read_text(encoding="utf-8")
            except FileNotFoundError:
                return exercise.starter

    def has_changes(self, exercise: Exercise) -> bool:
        return self.code(exercise) != exercise.starter

    def save(self, exercise: Exercise, code: str) -> None:
        if len(code) > MAX_CODE_CHARS:
            raise CodeTooLong(f"the code is {len(code)} characters; the limit is {MAX_CODE_CHARS}")
        with self._lock:
            write_atomically(self._path(exercise), code)
        if "first_opened" not in self.progress.exercise(exercise.slug):
            self.progress.update_exercise(exercise.slug, first_opened=time.time())

    def reset(self, exercise: Exercise) -> str:
        """Back to the starter code (the caller asked the learner first)."""
        with self._lock:
            self._path(exercise).unlink(missing_ok=True)
        return exercise.starter

    def diff(self, exercise: Exercise) -> str:
        """What the learner changed, as a unified diff against the starter."""
        lines = difflib.unified_diff(
            exercise.starter.splitlines(keepends=True),
            self.code(exercise).splitlines(keepends=True),
            fromfile="starter.py",
            tofile="yours.py",
        )
        return "".join(lines)

    def script_for_run(self, exercise: Exercise) -> Path:
        """Copy the code into the scratch folder; the copy is what runs."""
        script = self.scratch / f"{exercise.slug}.py"
        write_atomically(script, self.code(exercise))
        return script

    def record_check(
        self, exercise: Exercise, passed: bool, mistake: str = "", seed: int | None = None
    ) -> dict:
        """One grading: counted, and on a failure the mistake it matched
        (``app.exercises.mistakes``), kept until the exercise passes; the first
        pass keeps its ``seed`` (the grade's comment in the LMS names it)."""
        changes: dict = {"attempts": Added(1), "last_checked": time.time()}
        if passed:
            changes["last_mistake"] = None  # removed: a pass leaves no mistake behind
            record = self.progress.exercise(exercise.slug)
            if "passed_at" not in record:
                changes["passed_at"] = time.time()
                if seed is not None:
                    changes["passed_seed"] = seed
                start = record.get("first_opened", time.time())
                changes["seconds_to_pass"] = round(time.time() - start, 1)
        else:
            changes["failed_checks"] = Added(1)
            changes["last_mistake"] = mistake or None
        return self.progress.update_exercise(exercise.slug, **changes)

    def passed(self, exercise: Exercise) -> bool:
        return "passed_at" in self.progress.exercise(exercise.slug)

    def may_see_solution(self, exercise: Exercise, reveal_after: int | None = None) -> bool:
        """After passing, or after the number of failed checks the teacher set."""
        record = self.progress.exercise(exercise.slug)
        limit = exercise.reveal_after if reveal_after is None else reveal_after
        return "passed_at" in record or record.get("failed_checks", 0) >= limit
