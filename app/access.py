"""The access token gate for a dashboard served beyond this machine.

viser has no authentication, and its websocket carries everything a page
shows and every click it sends. So the gate sits in front of both, at the
HTTP layer of the one ``websockets`` server viser runs: every request (the
page, and the websocket upgrade) must carry the token, either as
``?token=...`` in the URL, as the cookie the first good request sets, or in
the ``X-Classroom-Token`` header (a trusted proxy in front, such as
Jupyter's server proxy, adds it to every request it forwards).
Without it the answer is ``401`` and no websocket ever opens, so a stranger
can neither watch nor start, stop, publish or call anything.

viser builds its server inside a background thread with a private
``process_request``; we wrap ``websockets.asyncio.server.serve`` for the
moment ``ViserServer`` is constructed and compose our check in front of
viser's. If a future viser stops calling it, construction fails closed.
"""

from __future__ import annotations

import hmac
import http
import re
import secrets
import threading
from collections.abc import Awaitable, Callable, Iterator
from contextlib import contextmanager
from http.cookies import SimpleCookie
from typing import Any, Protocol
from urllib.parse import parse_qs, urlsplit

import viser
import websockets.asyncio.server as ws_server
from websockets.asyncio.server import ServerConnection
from websockets.http11 import Request, Response

from app import viser_icons, viser_input, viser_threads, ws_handshake_log

TOKEN_ENV = "CLASSROOM_TOKEN"
TOKEN_HEADER = "X-Classroom-Token"
_TOKEN_SHAPE = re.compile(r"^[A-Za-z0-9_-]{16,128}$")
_PATCH_LOCK = threading.Lock()

ProcessRequest = Callable[[ServerConnection, Request], Response | None]
Handler = Callable[[ServerConnection], Awaitable[None]]
# What websockets' ``serve`` takes as ``process_request``: a function or a coroutine function.
GateProcessRequest = Callable[
    [ServerConnection, Request], Awaitable[Response | None] | Response | None
]


class AccessError(ValueError):
    """A token the user chose that would be unsafe or unusable in a URL."""


def new_token() -> str:
    """A fresh random token (128 bits), safe to put in a URL."""
    return secrets.token_urlsafe(16)


def check_token(token: str) -> str:
    if not _TOKEN_SHAPE.match(token):
        raise AccessError("an access token needs 16-128 characters from A-Z, a-z, 0-9, '-' and '_'")
    return token


class TokenGate:
    """Decides, per HTTP request, whether it carries the token."""

    def __init__(self, token: str, port: int) -> None:
        self._token = check_token(token).encode()
        # Browsers share cookies across ports of one host: name it per port so
        # several classroom instances on one machine keep separate tokens.
        self.cookie_name = f"classroom_token_{port}"
        self.installed = False
        self.rejected = 0

    def _matches(self, candidate: str | None) -> bool:
        return candidate is not None and hmac.compare_digest(candidate.encode(), self._token)

    def _from_query(self, request: Request) -> str | None:
        values = parse_qs(urlsplit(request.path).query).get("token")
        return values[0] if values else None

    def _from_cookie(self, request: Request) -> str | None:
        jar = SimpleCookie()
        for header in request.headers.get_all("Cookie"):
            try:
                jar.load(header)
            except Exception:  # a garbled cookie header is just "no token"
                continue
        morsel = jar.get(self.cookie_name)
        return morsel.value if morsel else None

    def wrap(self, inner: ProcessRequest | None) -> ProcessRequest:
        """Our check first; viser's file server (``inner``) only for admitted requests."""

        def process_request(connection: ServerConnection, request: Request) -> Response | None:
            by_query = self._matches(self._from_query(request))
            by_header = self._matches(request.headers.get(TOKEN_HEADER))
            if not (by_query or by_header or self._matches(self._from_cookie(request))):
                self.rejected += 1
                return connection.respond(
                    http.HTTPStatus.UNAUTHORIZED,
                    "This ROS 2 Classroom dashboard needs its access token: open the full "
                    "URL the teacher's `ros2-classroom serve` printed (it ends in ?token=...).\n",
                )
            if not same_origin(request):
                self.rejected += 1
                return connection.respond(http.HTTPStatus.FORBIDDEN, "Cross-site request.\n")
            response = inner(connection, request) if inner is not None else None
            if response is not None and by_query:
                response.headers["Set-Cookie"] = (
                    f"{self.cookie_name}={self._token.decode()}; Path=/; HttpOnly; SameSite=Strict"
                )
            return response

        return process_request


def same_origin(request: Request) -> bool:
    """A websocket opened by another site's page (cross-site hijacking) is refused."""
    origin = request.headers.get("Origin")
    if origin is None or request.headers.get("Upgrade", "").lower() != "websocket":
        return True
    return urlsplit(origin).netloc == request.headers.get("Host", "")


class Gate(Protocol):
    """Who may reach the server at all: checked before every route (``TokenGate``, or a hub login).

    ``wrap`` may return a coroutine function (websockets awaits it); a gate that
    also defines ``wrap_handler`` sees every websocket connection it admitted.
    """

    installed: bool

    def wrap(self, inner: ProcessRequest | None) -> GateProcessRequest: ...


class ServerExtension(Protocol):
    """Extra HTTP routes and websocket paths on viser's server (the exercise editor)."""

    def wrap_http(self, inner: ProcessRequest | None) -> ProcessRequest: ...

    def wrap_handler(self, inner: Handler) -> Handler: ...


@contextmanager
def _extended_serve(gate: Gate | None, extension: ServerExtension | None) -> Iterator[None]:
    """While viser builds its server: our routes behind the gate, the gate in front of all."""
    original = ws_server.serve

    def serve(handler: Handler, *args: Any, **kwargs: Any) -> ws_server.serve:
        process_request = kwargs.get("process_request")
        if extension is not None:
            process_request = extension.wrap_http(process_request)
            handler = extension.wrap_handler(handler)
        if gate is not None:
            process_request = gate.wrap(process_request)
            gate.installed = True
            wrap_handler = getattr(gate, "wrap_handler", None)
            if wrap_handler is not None:
                handler = wrap_handler(handler)
        kwargs["process_request"] = process_request
        return original(handler, *args, **kwargs)

    with _PATCH_LOCK:
        ws_server.serve = serve  # type: ignore[assignment,misc]
        try:
            yield
        finally:
            ws_server.serve = original  # type: ignore[misc]


def make_server(
    host: str,
    port: int,
    token: str | None,
    extension: ServerExtension | None = None,
    gate: Gate | None = None,
) -> tuple[viser.ViserServer, Gate | None]:
    """A viser server; with a token (or another ``gate``: a JupyterHub login,
    app/hub/singleuser_auth.py), every request must pass it (fails closed)."""
    if token is not None and gate is not None:
        raise ValueError("one gate: an access token or another gate, not both")
    # Before the server exists: it makes its broadcast buffer as it starts.
    viser_threads.install()
    viser_icons.install()
    viser_input.install()
    ws_handshake_log.install()
    if token is None and extension is None and gate is None:
        return viser.ViserServer(host=host, port=port, verbose=False), None
    if token is not None:
        gate = TokenGate(token, port)
    with _extended_serve(gate, extension):
        server = viser.ViserServer(host=host, port=port, verbose=False)
    if gate is not None and not gate.installed:
        server.stop()
        raise RuntimeError("could not install the access token gate in this viser version")
    return server, gate
