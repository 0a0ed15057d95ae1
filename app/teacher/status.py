"""``ros2-classroom classroom status``: the teacher page's table, in a terminal.

The running ``classroom`` command writes where its teacher page is (URL and
token, readable by its user only) beside the learners' progress; ``status``
reads that file and asks the page for its table, so both always show the
same rows. A fresh DDS participant would need seconds of discovery before
it heard every learner; the page has been listening all along.
"""

from __future__ import annotations

import json
import os
import urllib.error
import urllib.request
from pathlib import Path
from urllib.parse import urlsplit

from app.teacher.record import text_table

TEACHER_FILE = "teacher.json"


class StatusError(RuntimeError):
    """Why the table could not be fetched, in one line."""


def write_teacher_file(progress_root: Path, url: str, token: str) -> Path:
    """Where ``status`` finds the page: a file only this user can read."""
    progress_root.mkdir(parents=True, exist_ok=True, mode=0o700)
    path = progress_root / TEACHER_FILE
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w", encoding="utf-8") as handle:
        json.dump({"url": url, "token": token, "pid": os.getpid()}, handle)
    return path


def remove_teacher_file(progress_root: Path) -> None:
    (progress_root / TEACHER_FILE).unlink(missing_ok=True)


def read_teacher_file(progress_root: Path) -> tuple[str, str]:
    path = progress_root / TEACHER_FILE
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        return str(data["url"]), str(data["token"])
    except FileNotFoundError:
        raise StatusError(
            f"no classroom is running with progress in {progress_root} (no {TEACHER_FILE}); "
            "start one with `ros2-classroom classroom --learners N`, or pass --progress-dir"
        ) from None
    except (ValueError, KeyError, TypeError) as exc:
        raise StatusError(f"{path} is unreadable ({exc})") from None


def fetch_table(url: str, token: str, timeout: float = 5.0) -> dict:
    parts = urlsplit(url)
    target = f"{parts.scheme}://{parts.netloc}/classroom/teacher/progress.json?token={token}"
    try:
        with urllib.request.urlopen(target, timeout=timeout) as answer:
            return json.loads(answer.read().decode("utf-8"))
    except urllib.error.HTTPError as exc:
        raise StatusError(f"the teacher page at {parts.netloc} refused: HTTP {exc.code}") from None
    except (urllib.error.URLError, OSError) as exc:
        reason = getattr(exc, "reason", exc)
        raise StatusError(
            f"cannot reach the teacher page at {parts.netloc} ({reason}); is the classroom running?"
        ) from None


def render(answer: dict) -> str:
    rows = answer.get("rows", [])
    if not rows:
        return "No learner has reported yet."
    columns = tuple(answer.get("columns", ()))
    return text_table(rows, columns) + f"\n\n{len(rows)} learner{'s' if len(rows) != 1 else ''}."


def status(progress_root: Path) -> str:
    url, token = read_teacher_file(progress_root)
    return render(fetch_table(url, token))
