"""A learner's progress report over HTTP: the record as JSON, checked field by field.

On a JupyterHub the learners' dashboards live in separate pods or processes
with no multicast between them, so each dashboard POSTs its record to the
teacher service (app/hub/teacher_service.py). Whatever arrives is untrusted:
every field must have its record type, texts are clipped to the record's
bounds, and unknown fields are refused, so a bad report gets a clear reason
and never a half-filled row.
"""

from __future__ import annotations

import json
from dataclasses import asdict, fields
from typing import Any

from app.teacher import record as rec
from app.teacher.record import GradedAttempt, LearnerRecord, clip
from app.teacher.time_spent import KEY as ACTIVITY_KEY
from app.teacher.time_spent import MAX_ACTIVITIES

MAX_BODY = 128 * 1024  # the longest code excerpt and ten attempts: about 30 kB of ASCII

_TEXT_LIMITS = {
    "site": rec.MAX_NAME,
    "learner": rec.MAX_NAME,
    "lesson_id": rec.MAX_NAME,
    "lesson_title": rec.MAX_TITLE,
    "step_title": rec.MAX_TITLE,
    "exercise": rec.MAX_NAME,
    "exercise_mistake": rec.MAX_MISTAKE,
    "code_excerpt": rec.MAX_CODE,
    "last_error": rec.MAX_ERROR,
}
_INTS = {
    "domain_id", "unit", "step", "steps", "steps_passed", "exercises_passed",
    "exercise_attempts", "exercise_attempts_here", "exercise_failed_here",
    "exercise_passed_seed",
}  # fmt: skip
_FLOATS = {"last_activity", "last_progress"}
_LISTS = {
    "check_states": (rec.MAX_CHECKS, 8),
    "check_reasons": (rec.MAX_CHECKS, rec.MAX_REASON),
    "nodes_running": (rec.MAX_NODES, rec.MAX_NAME),
}
SENT_FIELDS = tuple(f.name for f in fields(LearnerRecord) if f.name != "received_at")


class ReportError(ValueError):
    """Why a report was refused (shown to whoever sent it)."""


def to_json(record: LearnerRecord) -> bytes:
    data = asdict(record)
    data.pop("received_at")
    return json.dumps(data).encode()


def from_json(body: bytes, received_at: float) -> LearnerRecord:
    """A record from a report body; raises ReportError with the first thing wrong."""
    if len(body) > MAX_BODY:
        raise ReportError(f"a progress report may have at most {MAX_BODY} bytes")
    try:
        data = json.loads(body)
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ReportError(f"a progress report must be JSON: {error}") from None
    if not isinstance(data, dict):
        raise ReportError("a progress report must be a JSON object")
    unknown = sorted(set(data) - set(SENT_FIELDS))
    if unknown:
        raise ReportError(f"unknown field(s) in the progress report: {', '.join(unknown)}")
    values: dict[str, Any] = {}
    for name, value in data.items():
        values[name] = _field(name, value)
    if not values.get("learner"):
        raise ReportError("a progress report must name its learner")
    return LearnerRecord(**values, received_at=received_at)


def _field(name: str, value: object) -> object:
    if name in _TEXT_LIMITS:
        if not isinstance(value, str):
            raise ReportError(f"{name} must be a string")
        return clip(value, _TEXT_LIMITS[name])
    if name in _INTS:
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < 2**31:
            raise ReportError(f"{name} must be a whole number from 0 to 2^31-1")
        return value
    if name in _FLOATS:
        if isinstance(value, bool) or not isinstance(value, int | float) or not 0 <= value < 1e11:
            raise ReportError(f"{name} must be a time in seconds since 1970")
        return float(value)
    if name == "exercise_passed_here":
        if not isinstance(value, bool):
            raise ReportError(f"{name} must be true or false")
        return value
    if name == "time_spent":
        return _time_spent(value)
    if name == "exercise_history":
        if not isinstance(value, list):
            raise ReportError(f"{name} must be a list of attempts")
        return tuple(_attempt(item) for item in value[: rec.MAX_HISTORY])
    count, limit = _LISTS[name]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ReportError(f"{name} must be a list of strings")
    return tuple(clip(v, limit) for v in value[:count])


def _time_spent(value: object) -> tuple[tuple[str, int], ...]:
    """[["lesson:05_topics", 1234], ...]: named activities, whole seconds."""
    what = "time_spent must be a list of [activity, seconds] pairs"
    if not isinstance(value, list) or len(value) > MAX_ACTIVITIES:
        raise ReportError(f"{what}, at most {MAX_ACTIVITIES}")
    pairs = []
    for pair in value:
        if not isinstance(pair, list) or len(pair) != 2:
            raise ReportError(what)
        key, seconds = pair
        if not isinstance(key, str) or not ACTIVITY_KEY.fullmatch(key):
            raise ReportError(f"{what}: an activity is lesson:ID or exercise:SLUG")
        if isinstance(seconds, bool) or not isinstance(seconds, int) or not 0 <= seconds < 2**31:
            raise ReportError(f"{what}: seconds must be a whole number from 0 to 2^31-1")
        pairs.append((key, seconds))
    return tuple(pairs)


_ATTEMPT_FIELDS = tuple(f.name for f in fields(GradedAttempt))


def _attempt(item: object) -> GradedAttempt:
    """One attempt of ``exercise_history``, checked as strictly as the record around it."""
    what = "each attempt of exercise_history"
    if not isinstance(item, dict) or set(item) - set(_ATTEMPT_FIELDS) or "at" not in item:
        raise ReportError(f"{what} must be an object with {', '.join(_ATTEMPT_FIELDS)}")
    at = item["at"]
    if isinstance(at, bool) or not isinstance(at, int | float) or not 0 <= at < 1e11:
        raise ReportError(f"{what} needs its time in seconds since 1970 (at)")
    verdict = item.get("verdict")
    if verdict not in rec.VERDICTS:
        raise ReportError(f"{what} needs a verdict of {', '.join(rec.VERDICTS)}")
    numbers = {}
    for key in ("seed", "passed", "total"):
        number = item.get(key, 0)
        if isinstance(number, bool) or not isinstance(number, int) or not 0 <= number < 2**32:
            raise ReportError(f"{what}: {key} must be a whole number from 0 to 2^32-1")
        numbers[key] = number
    failed = item.get("failed", [])
    if not isinstance(failed, list) or not all(isinstance(f, str) for f in failed):
        raise ReportError(f"{what}: failed must be a list of strings")
    summary = item.get("summary", "")
    if not isinstance(summary, str):
        raise ReportError(f"{what}: summary must be a string")
    graded_file = item.get("graded_file", "")
    if (
        not isinstance(graded_file, str)
        or len(graded_file) > rec.MAX_GRADED_FILE
        or not graded_file.isprintable()  # it ends up in a command a teacher copies
    ):
        raise ReportError(
            f"{what}: graded_file must be a path of at most {rec.MAX_GRADED_FILE} characters"
        )
    return GradedAttempt(
        at=float(at),
        verdict=verdict,
        failed=tuple(clip(f, rec.MAX_REASON) for f in failed[: rec.MAX_FAILED]),
        summary=clip(summary, rec.MAX_SUMMARY),
        graded_file=graded_file,
        **numbers,
    )
