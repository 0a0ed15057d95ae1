"""A learner's progress on disk, written atomically so a crash never loses it.

Each save writes a temporary file in the same directory, fsyncs it and renames
it over the old one (``os.replace`` is atomic on POSIX), then fsyncs the
directory. A SIGKILL at any moment leaves either the old or the new file. A
file that is corrupt anyway (edited by hand, disk trouble) is moved aside, not
deleted, and the learner starts fresh with a clear message.
"""

from __future__ import annotations

import json
import os
import re
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypedDict

from app import PROJECT_ROOT

DEFAULT_DIR = PROJECT_ROOT / "var" / "progress"
VERSION = 2
# Version 2 numbered the lessons 1..N in course order and split two long ones. Old id ->
# (first old step, new id, step shift) per part: a saved step moves with the part it is in.
RENUMBERED_IN_V2: dict[str, tuple[tuple[int, str, int], ...]] = {
    **{
        old: ((0, new, 0),)
        for old, new in (
            ("02_first_node", "04_first_node"),
            ("03_topics", "05_topics"),
            ("04_qos", "06_qos"),
            ("05_services", "07_services"),
            ("06_interfaces", "08_interfaces"),
            ("07_actions", "09_actions"),
            ("08_parameters", "10_parameters"),
            ("09_lifecycle", "11_lifecycle"),
            ("10_launch", "12_launch"),
            ("11_executors", "13_executors"),
            ("12_images_opencv", "14_images_opencv"),
            ("13_frames_and_arm", "15_frames_and_arm"),
            ("13_urdf_robot", "18_urdf_robot"),
            ("13_wheeled_robot", "19_wheeled_robot"),
            ("15_workspaces_packages", "20_workspaces_packages"),
            ("16_bags", "21_bags"),
            ("14_slam_capstone", "22_slam_capstone"),
        )
    },
    "01_turtlesim_cli": ((0, "02_turtlesim_cli", 0), (6, "03_turtlesim_record_launch", -5)),
    "13_tf2_turtlesim": ((0, "16_tf2_turtlesim", 0), (12, "17_tf2_time", -12)),
}


class LessonRecord(TypedDict):
    """A lesson's progress: the step shown last and the steps passed."""

    step: int
    passed: list[int]


def _renumbered(lesson_id: str, step: int) -> tuple[str, int]:
    parts = RENUMBERED_IN_V2.get(lesson_id, ((0, lesson_id, 0),))
    _first, new_id, shift = max(part for part in parts if part[0] <= max(step, 0))
    return new_id, step + shift


def migrate(data: dict[str, Any]) -> dict[str, Any]:
    """A version-1 record, its lesson ids and steps moved to where those steps are now."""
    if data.get("version", 1) >= VERSION:
        return data
    lessons: dict[str, LessonRecord] = {}
    for old_id, entry in data["lessons"].items():
        for step in sorted(int(s) for s in entry.get("passed", [])):
            new_id, new_step = _renumbered(old_id, step)
            moved = lessons.setdefault(new_id, {"step": 0, "passed": []})
            moved["passed"] = sorted({*moved["passed"], new_step})
        new_id, new_step = _renumbered(old_id, int(entry.get("step", 0)))
        lessons.setdefault(new_id, {"step": 0, "passed": []})["step"] = new_step
    current = data.get("current")
    if isinstance(current, str):
        step = int(data["lessons"].get(current, {}).get("step", 0))
        data["current"] = _renumbered(current, step)[0]
    return {**data, "version": VERSION, "lessons": lessons}


_NAME = re.compile(r"^[A-Za-z0-9_-]{1,64}$")


class Added:
    """``update_exercise(slug, attempts=Added(1))``: a counter increment."""

    def __init__(self, amount: int) -> None:
        self.amount = amount


class ProgressStore:
    def __init__(self, learner: str = "default", directory: Path = DEFAULT_DIR) -> None:
        if not _NAME.match(learner):
            raise ValueError("learner names use letters, digits, '-' and '_' (1-64 characters)")
        self.path = directory / f"{learner}.json"
        self.warning = ""
        self._lock = threading.Lock()
        self._data = self._load()
        self._listeners: list[Callable[[], None]] = []

    def on_change(self, listener: Callable[[], None]) -> None:
        """Call ``listener()`` after each save, on the saving thread and under the store's
        lock: it must only note the change (set an event), never read the store."""
        self._listeners.append(listener)

    def _load(self) -> dict[str, Any]:
        try:
            data = json.loads(self.path.read_text(encoding="utf-8"))
            if not isinstance(data, dict) or not isinstance(data.get("lessons"), dict):
                raise ValueError("unexpected layout")
            return migrate(data)
        except FileNotFoundError:
            return {"version": VERSION, "lessons": {}}
        except (ValueError, TypeError, UnicodeDecodeError) as exc:
            aside = self.path.with_suffix(f".corrupt-{int(time.time())}.json")
            os.replace(self.path, aside)
            self.warning = f"Progress file was unreadable ({exc}); kept it as {aside.name}."
            return {"version": VERSION, "lessons": {}}

    def lesson(self, lesson_id: str) -> LessonRecord:
        with self._lock:
            entry = self._data["lessons"].get(lesson_id, {})
            return {"step": int(entry.get("step", 0)), "passed": list(entry.get("passed", []))}

    def current_lesson(self) -> str | None:
        with self._lock:
            return self._data.get("current")

    def set_position(self, lesson_id: str, step: int) -> None:
        with self._lock:
            entry = self._data["lessons"].setdefault(lesson_id, {"step": 0, "passed": []})
            entry["step"] = step
            self._data["current"] = lesson_id
            self._save()

    def mark_passed(self, lesson_id: str, step: int) -> bool:
        """Record a passed step; returns True when this is news."""
        with self._lock:
            entry = self._data["lessons"].setdefault(lesson_id, {"step": step, "passed": []})
            if step in entry["passed"]:
                return False
            entry["passed"] = sorted({*entry["passed"], step})
            self._save()
            return True

    def exercise(self, slug: str) -> dict[str, Any]:
        """An exercise's record: attempts, failed checks, first opened, passed at."""
        with self._lock:
            return dict(self._data.get("exercises", {}).get(slug, {}))

    def update_exercise(
        self, slug: str, **changes: int | float | str | Added | None
    ) -> dict[str, Any]:
        """Merge ``changes`` into the exercise's record (numbers given as +N are added)."""
        with self._lock:
            record = self._data.setdefault("exercises", {}).setdefault(slug, {})
            for key, value in changes.items():
                if isinstance(value, Added):
                    record[key] = record.get(key, 0) + value.amount
                elif value is None:
                    record.pop(key, None)
                else:
                    record[key] = value
            self._save()
            return dict(record)

    def reset(self) -> None:
        with self._lock:
            self._data = {"version": VERSION, "lessons": {}}
            self._save()

    def _save(self) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".progress-", dir=self.path.parent)
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as handle:
                json.dump(self._data, handle, indent=1, sort_keys=True)
                handle.flush()
                os.fsync(handle.fileno())
            os.replace(tmp, self.path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        dir_fd = os.open(self.path.parent, os.O_RDONLY)
        try:
            os.fsync(dir_fd)
        finally:
            os.close(dir_fd)
        for listener in self._listeners:
            listener()
