"""The real teacher service for the LTI tests: its tornado app on a loopback port, in a thread.

No JupyterHub: what the service asks the hub is answered by ``TestHub``, a
stand-in. Whose API token a progress report or a teacher's page carries it
answers over HTTP, at the hub API's ``/user`` as JupyterHub does, to the
service's real ``ServiceAuth`` (app/hub/service_auth.py), which then checks
the user's scopes itself.
Everything else is the service as it runs: ``make_app`` with its LTI side,
the tool's folder on disk, the outbox pump on tornado's loop, and real HTTP
in and out.
"""

from __future__ import annotations

import asyncio
import http.client
import json
import threading
import time
import urllib.parse
from collections.abc import Callable
from dataclasses import dataclass, field
from http.cookies import SimpleCookie
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any, Protocol

from tornado.httpserver import HTTPServer
from tornado.netutil import bind_sockets

from app.hub.lti_service import LtiService
from app.hub.service_auth import ServiceAuth, ServiceSettings
from app.hub.teacher_service import SERVICE_NAME, make_app
from app.lti.routes import ToolUrls
from app.lti.tool import LtiTool
from app.teacher.http_report import to_json
from app.teacher.record import LearnerRecord

PREFIX = "/services/classroom-teacher/"
HUB_BASE = "/"


TEACHER_SCOPE = f"access:services!service={SERVICE_NAME}"  # what the hub's teachers role grants


class TestHub:
    """Whose hub API token is whose, as the hub would answer the service's questions.

    Its ``/hub/api/user`` answers as JupyterHub's does: the token's user with
    their scopes (a teacher's token carries the service's access scope, as the
    deployment's teachers role grants it; a learner's does not).
    """

    __test__ = False

    def __init__(self) -> None:
        self._tokens: dict[str, str] = {}
        self._scopes: dict[str, list[str]] = {}
        self._codes: dict[str, str] = {}  # OAuth code -> the token it is exchanged for
        self._server = ThreadingHTTPServer(("127.0.0.1", 0), self._handler())
        self._thread = threading.Thread(
            target=self._server.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True
        )
        self._thread.start()
        self.api_url = f"http://127.0.0.1:{self._server.server_address[1]}/hub/api"

    def close(self) -> None:
        self._server.shutdown()
        self._server.server_close()
        self._thread.join(timeout=5)

    def token_for(self, name: str) -> str:
        token = f"token-of-{name}"
        self._tokens[token] = name
        self._scopes.setdefault(
            token, [f"access:servers!user={name}", f"read:users:name!user={name}"]
        )
        return token

    def teacher_token(self, name: str) -> str:
        token = self.token_for(name)
        self._scopes[token] = [*self._scopes[token], TEACHER_SCOPE]
        return token

    def auth(self) -> ServiceAuth:
        """The service's hub login as the hub's environment would set it up, aimed here."""
        env = {
            "JUPYTERHUB_API_URL": self.api_url,
            "JUPYTERHUB_API_TOKEN": "token-of-the-service",
            "JUPYTERHUB_SERVICE_PREFIX": PREFIX,
            "JUPYTERHUB_OAUTH_ACCESS_SCOPES": json.dumps([TEACHER_SCOPE]),
        }
        return ServiceAuth(ServiceSettings.from_env(SERVICE_NAME, env), cache_sec=0)

    def code_for(self, token: str) -> str:
        """The code the hub's authorize page would send a browser back with, for ``token``."""
        code = f"code-{len(self._codes)}"
        self._codes[code] = token
        return code

    def _model(self, authorization: str) -> dict[str, Any] | None:
        token = authorization.partition(" ")[2].strip()
        name = self._tokens.get(token)
        if name is None:
            return None
        return {"kind": "user", "name": name, "admin": False, "groups": [],
                "scopes": self._scopes[token]}  # fmt: skip

    def _handler(self) -> type[BaseHTTPRequestHandler]:
        hub = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, format: str, *args: Any) -> None:
                pass

            def do_GET(self) -> None:
                model = hub._model(self.headers.get("Authorization", ""))
                status = 200 if model and self.path == "/hub/api/user" else 403
                body = json.dumps(model if status == 200 else {"error": "no such token"})
                self.send_response(status)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body.encode())

            def do_POST(self) -> None:  # the OAuth token endpoint: a code for its token
                length = int(self.headers.get("Content-Length") or 0)
                form = dict(urllib.parse.parse_qsl(self.rfile.read(length).decode()))
                token = hub._codes.pop(form.get("code", ""), None)
                ok = self.path == "/hub/api/oauth2/token" and token is not None
                body = json.dumps({"access_token": token} if ok else {"error": "invalid_grant"})
                self.send_response(200 if ok else 400)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body.encode())

        return Handler


class ToolUnderTest(Protocol):
    """A running tool the test LMS launches: the hub's teacher service, or a classroom's."""

    @property
    def urls(self) -> ToolUrls: ...


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
    cookies: dict[str, str] = field(default_factory=dict)  # every Set-Cookie, by name

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
        jar = SimpleCookie()
        for name, value in response.getheaders():
            if name.lower() == "set-cookie":
                jar.load(value)
        return Answer(
            response.status,
            {k.lower(): v for k, v in response.getheaders()},
            text,
            {name: morsel.value for name, morsel in jar.items()},
        )
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
        app = make_app(PREFIX, auth=self.hub.auth(), lti=self.lti)
        self._server = HTTPServer(app)
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
        self.hub.close()

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


def wait_delivered(lti: LtiService, why: str, timeout: float = 10.0) -> None:
    """Until the tool has the LMS's answer to a score: its outbox says delivered.

    The LMS holds a score a moment before the tool hears back, and the teacher's pages
    say "✓ sent" only then (a rehearsal at load 12.7 read a page in between).
    """
    wait_for(lambda: any(e.status == "delivered" for e in lti.tool.outbox.entries()), timeout, why)
