"""The real teacher service for the LTI tests: its tornado app on a loopback port, in a thread.

No JupyterHub: the one thing the service asks the hub (whose API token a
progress report carries) is answered by ``TestHub``, a stand-in with the
same two calls as ``HubAuth``. Everything else is the service as it runs:
``make_app`` with its LTI side, the tool's folder on disk, the outbox pump on
tornado's loop, and real HTTP in and out.
"""

from __future__ import annotations

import asyncio
import http.client
import threading
import time
import urllib.parse
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tornado.httpserver import HTTPServer
from tornado.netutil import bind_sockets

from app.hub.lti_service import LtiService
from app.hub.teacher_service import make_app
from app.lti.routes import ToolUrls
from app.lti.tool import LtiTool
from app.teacher.http_report import to_json
from app.teacher.record import LearnerRecord

PREFIX = "/services/classroom-teacher/"
HUB_BASE = "/"


class TestHub:
    """Whose hub API token is whose, as the hub would answer ``HubAuth``'s questions."""

    __test__ = False

    def __init__(self) -> None:
        self._tokens: dict[str, str] = {}

    def token_for(self, name: str) -> str:
        token = f"token-of-{name}"
        self._tokens[token] = name
        return token

    def get_token(self, handler: Any, in_cookie: bool = True) -> str | None:
        header = handler.request.headers.get("Authorization", "")
        return header.removeprefix("token ").strip() or None

    async def user_for_token(self, token: str, sync: bool = True) -> dict[str, str] | None:
        name = self._tokens.get(token)
        return {"name": name, "kind": "user"} if name else None


class Clock:
    """Wall-clock time that a test can move ahead (the outbox's backoff waits on it)."""

    def __init__(self) -> None:
        self.ahead = 0.0

    def __call__(self) -> float:
        return time.time() + self.ahead


@dataclass
class Answer:
    status: int
    headers: dict[str, str]
    body: str

    @property
    def location(self) -> str:
        return self.headers.get("location", "")


def request(
    method: str,
    url: str,
    form: dict[str, Any] | None = None,
    headers: dict[str, str] | None = None,
    body: bytes | None = None,
) -> Answer:
    """One HTTP request, redirects not followed (the test looks at where they point)."""
    parts = urllib.parse.urlsplit(url)
    connection = http.client.HTTPConnection(parts.hostname or "", parts.port, timeout=15)
    if form is not None:
        body = urllib.parse.urlencode(form, doseq=True).encode()
    sent = dict(headers or {})
    if form is not None:
        sent.setdefault("Content-Type", "application/x-www-form-urlencoded")
    try:
        path = parts.path + (f"?{parts.query}" if parts.query else "")
        connection.request(method, path, body=body, headers=sent)
        response = connection.getresponse()
        text = response.read().decode("utf-8", "replace")
        return Answer(response.status, {k.lower(): v for k, v in response.getheaders()}, text)
    finally:
        connection.close()


class ServiceUnderTest:
    """``make_app`` with LTI on a free loopback port, until ``close``."""

    __test__ = False

    def __init__(self, folder: Path, clock: Clock | None = None, poll_sec: float = 0.05) -> None:
        self.folder, self.hub = folder, TestHub()
        self.clock = clock or Clock()
        sockets = bind_sockets(0, "127.0.0.1")
        self.url = f"http://127.0.0.1:{sockets[0].getsockname()[1]}"
        self.base = self.url + PREFIX.rstrip("/")
        self.urls = ToolUrls.from_base(self.base)
        self.tool = LtiTool(folder, self.urls, clock=self.clock)
        self._loop = asyncio.new_event_loop()
        self._ready = threading.Event()
        self._thread = threading.Thread(
            target=self._run, args=(sockets, poll_sec), name="teacher-service", daemon=True
        )
        self._thread.start()
        if not self._ready.wait(15):
            raise RuntimeError("the teacher service did not start")

    def _run(self, sockets: list[Any], poll_sec: float) -> None:
        asyncio.set_event_loop(self._loop)
        self.lti = LtiService(
            self.tool, service_prefix=PREFIX, hub_base=HUB_BASE, poll_sec=poll_sec
        )
        self._server = HTTPServer(make_app(PREFIX, hub_auth=self.hub, lti=self.lti))
        self._server.add_sockets(sockets)
        self.lti.start()
        self._ready.set()
        self._loop.run_forever()

    def close(self) -> None:
        def stop() -> None:
            self._server.stop()
            self.lti.stop()
            self._loop.stop()

        self._loop.call_soon_threadsafe(stop)
        self._thread.join(timeout=15)
        self._loop.close()

    def report(self, record: LearnerRecord) -> Answer:
        """A learner's dashboard posting its progress with its own hub token."""
        return request(
            "POST",
            self.url + PREFIX + "api/progress",
            body=to_json(record),
            headers={
                "Authorization": f"token {self.hub.token_for(record.learner)}",
                "Content-Type": "application/json",
            },
        )


def wait_for(what: Callable[[], bool], timeout: float = 10.0, why: str = "") -> None:
    deadline = time.monotonic() + timeout
    while not what():
        if time.monotonic() > deadline:
            raise AssertionError(f"not within {timeout} s: {why}")
        time.sleep(0.02)
