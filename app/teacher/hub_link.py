"""A learner dashboard's link to the teacher service on a JupyterHub, over plain HTTP.

The beacon (app/teacher/beacon.py) hands each record to ``send`` on its own
thread. We POST it with the learner's own hub API token; the answer carries
the teacher's new messages and the reveal setting. A failed POST raises: an
unreachable service gets the newest record again a second later, a
refusal (4xx/5xx, its reason logged) a heartbeat later. The record is the
learner's whole state, so nothing is lost by a dropped report, and a
restarted service has every row back within a heartbeat.
"""

from __future__ import annotations

import json
import os
import urllib.error
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass

from app.teacher.http_report import to_json
from app.teacher.record import LearnerRecord

URL_ENV = "CLASSROOM_TEACHER_URL"
TOKEN_ENV = "JUPYTERHUB_API_TOKEN"
USER_ENV = "JUPYTERHUB_USER"
TIMEOUT_SEC = 5.0

NoticeSink = Callable[[str, str, float], None]  # (to, text, stamp)
SettingsSink = Callable[[int], None]  # reveal after N failed checks (0: exercise's own)


@dataclass(frozen=True)
class HubTarget:
    """Where the teacher service is and who this learner is, as the hub tells its server."""

    url: str  # the service's base URL, ending in /
    token: str
    learner: str

    @classmethod
    def from_env(cls, env: dict[str, str] | None = None) -> HubTarget | None:
        """Set inside a hub's single-user server whose operator registered the service."""
        env = dict(os.environ) if env is None else env
        url, token, user = env.get(URL_ENV), env.get(TOKEN_ENV), env.get(USER_ENV)
        if not (url and token and user):
            return None
        return cls(url.rstrip("/") + "/", token, user)


class ReportRefused(RuntimeError):
    """The service answered with an error status (its reason included)."""


class HubLink:
    heartbeat_sec = 2.0  # also how soon a teacher's message arrives

    def __init__(self, target: HubTarget, on_notice: NoticeSink, on_settings: SettingsSink) -> None:
        self._target = target
        self._on_notice, self._on_settings = on_notice, on_settings
        self._since = 0
        self._epoch: str | None = None
        self._reveal: int | None = None

    def send(self, record: LearnerRecord) -> None:
        request = urllib.request.Request(
            f"{self._target.url}api/progress?since={self._since}",
            data=to_json(record),
            method="POST",
            headers={
                "Authorization": f"token {self._target.token}",
                "Content-Type": "application/json",
            },
        )
        try:
            with urllib.request.urlopen(request, timeout=TIMEOUT_SEC) as answer:
                reply = json.loads(answer.read())
        except urllib.error.HTTPError as error:
            raise ReportRefused(f"{error.code}: {error.read()[:300]!r}") from None
        epoch = str(reply.get("epoch", ""))
        if epoch != self._epoch:  # a restarted service numbers its notices from 1 again
            if self._epoch is not None and self._since:
                self._since = 0
                self._epoch = epoch
                return  # the next report (a heartbeat away) fetches them all
            self._epoch = epoch
        for notice in reply.get("notices", []):
            self._since = max(self._since, int(notice["id"]))
            self._on_notice(str(notice["to"]), str(notice["text"]), float(notice["stamp"]))
        reveal = int(reply.get("reveal_after", 0))
        if reveal != self._reveal:
            self._reveal = reveal
            self._on_settings(reveal)

    def close(self) -> None:
        return
