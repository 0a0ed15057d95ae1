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
from app.teacher.record import LearnerRecord, clip

MAX_BODY = 64 * 1024  # a record with the longest code excerpt is about 10 kB

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
    count, limit = _LISTS[name]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ReportError(f"{name} must be a list of strings")
    return tuple(clip(v, limit) for v in value[:count])
