"""Scores on their way to the LMS, kept on disk until the platform has them.

One JSON file holds one entry per learner and line item: the best score so
far and whether it is waiting, delivered or refused. It is rewritten whole
and atomically (temporary file, fsync, rename) after every change, and a
score is written down before anyone tries to send it, so a process killed
at any moment loses nothing: the next process on the same folder sends
what was waiting. A resend after a crash carries the same timestamp, which
the platform takes as the result it already has (see ags.py).

One process owns the file (the hub's service); threads in it may submit and
deliver at once.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any, Literal, Protocol

from app.jsonish import JSONObject
from app.lti.ags import PostOutcome
from app.lti.score import Score
from app.lti.state_file import save_json

OUTBOX_FILE = "outbox.json"
FIRST_RETRY_SEC = 5.0
LAST_RETRY_SEC = 600.0  # a platform down for hours is asked every ten minutes

Status = Literal["pending", "delivered", "failed"]


class ScoreSender(Protocol):
    def post(self, issuer: str, client_id: str, lineitem: str, score: Score) -> PostOutcome: ...


@dataclass(frozen=True)
class OutboxEntry:
    issuer: str
    client_id: str
    lineitem: str
    score: Score
    status: Status = "pending"
    attempts: int = 0
    next_try: float = 0.0  # wall-clock seconds: it must survive a restart
    reason: str = ""  # the platform's last answer, for the teacher's page
    delivered_at: float | None = None

    @property
    def key(self) -> tuple[str, str]:
        return (self.lineitem, self.score.user_id)

    def to_json(self) -> JSONObject:
        return {**asdict(self), "score": self.score.to_ags()}

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> OutboxEntry:
        return cls(**{**data, "score": Score.from_ags(data["score"])})


def backoff_sec(attempts: int) -> float:
    """5 s, 10 s, 20 s, ... up to ten minutes between tries."""
    return float(min(LAST_RETRY_SEC, FIRST_RETRY_SEC * 2 ** max(0, attempts - 1)))


class Outbox:
    def __init__(
        self, folder: Path, sender: ScoreSender, *, clock: Callable[[], float] = time.time
    ) -> None:
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        self.path = folder / OUTBOX_FILE
        self._sender, self._clock = sender, clock
        self._lock = threading.Lock()
        self._delivering = threading.Lock()  # one round at a time: no score is sent twice at once
        self._entries: dict[tuple[str, str], OutboxEntry] = {}
        if self.path.exists():
            for data in json.loads(self.path.read_text(encoding="utf-8"))["entries"]:
                entry = OutboxEntry.from_json(data)
                self._entries[entry.key] = entry

    def submit(self, issuer: str, client_id: str, lineitem: str, score: Score) -> bool:
        """Queue ``score`` if it beats the learner's best on this line item; True if queued.

        A replacing score must carry a newer timestamp than the one it replaces, or the
        platform keeps the old one (Moodle answers 409); two results within the same
        millisecond get one millisecond apart.
        """
        with self._lock:
            best = self._entries.get((lineitem, score.user_id))
            if best is not None and not score.better_than(best.score):
                return False
            if best is not None:
                score = score.later_than(best.score)
            entry = OutboxEntry(issuer, client_id, lineitem, score, next_try=self._clock())
            self._entries[entry.key] = entry
            self._save()
            return True

    def entries(self) -> list[OutboxEntry]:
        """A snapshot, for the teacher's page: what was sent, what waits and why."""
        with self._lock:
            return list(self._entries.values())

    def retry_now(self) -> int:
        """Make every score not yet delivered due now (the teacher's Retry); the number.

        A refused score is tried again too: the teacher pressed Retry because the
        cause is fixed in the LMS (the learner enrolled, the column opened again).
        """
        with self._lock:
            now = self._clock()
            waiting = [e for e in self._entries.values() if e.status != "delivered"]
            for entry in waiting:
                self._entries[entry.key] = replace(entry, status="pending", next_try=now)
            if waiting:
                self._save()
            return len(waiting)

    def deliver_due(self) -> int:
        """Try every waiting score whose time has come; the number delivered."""
        with self._delivering:
            return self._deliver_round()

    def _deliver_round(self) -> int:
        with self._lock:
            now = self._clock()
            due = [e for e in self._entries.values() if e.status == "pending" and e.next_try <= now]
        delivered, down = 0, set[str]()
        for entry in due:
            if entry.issuer in down:
                continue  # that platform gave no answer just now: don't wait on each score
            outcome = self._sender.post(entry.issuer, entry.client_id, entry.lineitem, entry.score)
            if outcome.platform_down:
                down.add(entry.issuer)
            delivered += self._record(entry, outcome)
        return delivered

    def deliver_until(self, stop: threading.Event, poll_sec: float = 1.0) -> None:
        """Deliver in this thread until ``stop`` is set (the service runs it in a thread)."""
        while not stop.is_set():
            self.deliver_due()
            stop.wait(poll_sec)

    def _record(self, sent: OutboxEntry, outcome: PostOutcome) -> int:
        with self._lock:
            now = self._clock()
            current = self._entries.get(sent.key)
            if current is None or current.score != sent.score:
                return 0  # a better score came in meanwhile: it waits for its own turn
            attempts = current.attempts + 1
            if outcome.kind == "delivered":
                updated = replace(
                    current,
                    status="delivered",
                    attempts=attempts,
                    reason=outcome.reason,
                    delivered_at=now,
                )
            elif outcome.kind == "refused":
                updated = replace(
                    current, status="failed", attempts=attempts, reason=outcome.reason
                )
            else:
                wait = max(backoff_sec(attempts), outcome.retry_after_sec or 0.0)
                updated = replace(
                    current, attempts=attempts, next_try=now + wait, reason=outcome.reason
                )
            self._entries[sent.key] = updated
            self._save()
            return int(outcome.kind == "delivered")

    def _save(self) -> None:
        entries = [e.to_json() for e in self._entries.values()]
        save_json(self.path, {"version": 1, "entries": entries})
