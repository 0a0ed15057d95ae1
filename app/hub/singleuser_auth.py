"""The lean single-user mode: the dashboard is a learner's JupyterHub server, with hub OAuth.

In the Jupyter mode (app/hub/server_proxy.py) each learner's hub server is a
Jupyter server that starts the dashboard behind jupyter-server-proxy: about
105 MB of memory per learner just for Jupyter. In this mode the spawner runs
``ros2-classroom serve --jupyterhub`` instead, and this module does what
jupyterhub-singleuser would: JupyterHub's OAuth flow, as the hub documents it
for its servers and services (the steps ``jupyterhub.services.auth.HubOAuth``
takes, written here with the standard library only, since importing
jupyterhub's own client costs a learner ~36 MB):

1. A browser without our cookie is sent to the hub's authorize URL with a
   random ``state``, kept in a signed cookie of ours.
2. The hub logs the learner in (or already has) and, if the hub grants them
   access to this server (the owner, or an admin with access), sends the
   browser back to ``<prefix>oauth_callback`` with a code.
3. We check the state, exchange the code for a token at the hub's token URL
   (our server's API token as the client secret), ask the hub whose token it
   is and which scopes it holds, and keep the token in a signed, HttpOnly
   cookie scoped to this learner's path.

Every HTTP request and the websocket's upgrade then carry that cookie (or an
``Authorization: token`` header, as API clients send), and are let through
only if the hub says the token's owner may access this server (answers are
cached for five minutes, as HubAuth does). A token in a URL is never taken.
The hub's base path (``/user/<name>/``) is stripped before the dashboard's
own routes see a request, so every relative link works as under Jupyter's
proxy. The learner's clicks (websocket messages) and requests are reported
to the hub's activity API, so the hub's idle culler sees a learner at work.
"""

from __future__ import annotations

import http
import json
import logging
import os
import threading
import time
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from datetime import datetime, timezone
from email.utils import formatdate
from importlib import metadata
from typing import Any

from websockets.asyncio.server import ServerConnection
from websockets.datastructures import Headers
from websockets.http11 import Request, Response

from app.access import Handler, ProcessRequest, same_origin
from app.hub.hub_api import (
    STATE_MAX_AGE_SEC,
    AskHub,
    HubRefused,
    HubUsers,
    Signer,
    authorize_query,
    authorize_url,
    grants,
    header_token,
    hub_request,
    new_state,
    same_state,
)

log = logging.getLogger(__name__)

COOKIE_MAX_AGE_SEC = 14 * 24 * 3600
DEFAULT_ACTIVITY_SEC = 300  # jupyterhub-singleuser's default

_REQUIRED_ENV = (
    "JUPYTERHUB_API_TOKEN",
    "JUPYTERHUB_API_URL",
    "JUPYTERHUB_CLIENT_ID",
    "JUPYTERHUB_OAUTH_CALLBACK_URL",
    "JUPYTERHUB_SERVICE_PREFIX",
    "JUPYTERHUB_SERVICE_URL",
    "JUPYTERHUB_USER",
)

AsyncProcessRequest = Callable[[ServerConnection, Request], Awaitable[Response | None]]


class HubSettingsError(ValueError):
    """The environment a hub's spawner gives its servers is missing or wrong."""


@dataclass(frozen=True)
class HubSettings:
    """What the hub's spawner tells its single-user server, through the environment."""

    user: str
    server_name: str
    host: str
    port: int
    prefix: str  # /user/<name>/ (with the hub's own base URL in front, if any)
    api_url: str  # the hub's API, as this server reaches it
    api_token: str  # this server's own token; also the OAuth client's secret
    client_id: str
    callback_url: str
    authorize_url: str  # where browsers are sent to log in
    access_scopes: frozenset[str]
    activity_url: str
    activity_interval: float
    secure_cookies: bool

    @classmethod
    def from_env(cls, env: dict[str, str] | None = None) -> HubSettings:
        env = dict(os.environ) if env is None else env
        missing = [name for name in _REQUIRED_ENV if not env.get(name)]
        if missing:
            raise HubSettingsError(
                "--jupyterhub runs the dashboard as a JupyterHub single-user server: start it "
                f"from a hub's spawner (missing {', '.join(missing)})"
            )
        service = urllib.parse.urlsplit(env["JUPYTERHUB_SERVICE_URL"])
        if service.scheme != "http" or service.port is None:
            raise HubSettingsError(
                f"JUPYTERHUB_SERVICE_URL must be http://HOST:PORT/...: {service.geturl()!r} "
                "(internal TLS is not supported by the lean mode: use the Jupyter mode)"
            )
        prefix = env["JUPYTERHUB_SERVICE_PREFIX"]
        if not (prefix.startswith("/") and prefix.endswith("/")):
            raise HubSettingsError(f"JUPYTERHUB_SERVICE_PREFIX must start and end with /: {prefix}")
        try:
            scopes = frozenset(json.loads(env.get("JUPYTERHUB_OAUTH_ACCESS_SCOPES") or "[]"))
        except (ValueError, TypeError) as error:
            raise HubSettingsError(f"JUPYTERHUB_OAUTH_ACCESS_SCOPES is not JSON: {error}") from None
        if not scopes or not all(isinstance(s, str) for s in scopes):
            raise HubSettingsError("JUPYTERHUB_OAUTH_ACCESS_SCOPES names no scope")
        try:
            interval = float(env.get("JUPYTERHUB_ACTIVITY_INTERVAL") or DEFAULT_ACTIVITY_SEC)
        except ValueError:
            raise HubSettingsError("JUPYTERHUB_ACTIVITY_INTERVAL must be a number") from None
        # A hub on its own domain (subdomains) sets JUPYTERHUB_HOST; else browsers stay on ours.
        authorize = authorize_url(env)
        options = json.loads(env.get("JUPYTERHUB_COOKIE_OPTIONS") or "{}")
        return cls(
            user=env["JUPYTERHUB_USER"],
            server_name=env.get("JUPYTERHUB_SERVER_NAME", ""),
            host=service.hostname or "",
            port=service.port,
            prefix=prefix,
            api_url=env["JUPYTERHUB_API_URL"].rstrip("/"),
            api_token=env["JUPYTERHUB_API_TOKEN"],
            client_id=env["JUPYTERHUB_CLIENT_ID"],
            callback_url=env["JUPYTERHUB_OAUTH_CALLBACK_URL"],
            authorize_url=authorize,
            access_scopes=scopes,
            activity_url=env.get("JUPYTERHUB_ACTIVITY_URL", ""),
            activity_interval=interval,
            secure_cookies=bool(options.get("secure")),
        )


def _utc_stamp(when: float) -> str:
    return datetime.fromtimestamp(when, timezone.utc).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


class Activity:
    """The learner's last request or click, sent to the hub's activity API for its idle culler."""

    def __init__(self, settings: HubSettings, post: Callable[..., object] = hub_request) -> None:
        self._settings = settings
        self._post = post
        self.last = 0.0  # written from viser's thread, read here: a float, no lock needed
        self._sent = 0.0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def touch(self) -> None:
        self.last = time.time()

    def start(self) -> None:
        if not self._settings.activity_url or self._settings.activity_interval <= 0:
            log.warning("the hub gave no activity URL: the idle culler will not see this learner")
            return
        self._thread = threading.Thread(target=self._run, name="hub-activity", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()

    def report(self) -> bool:
        """Send the newest activity if there is news; True when the hub took it."""
        last = self.last
        if last <= self._sent:
            return False
        stamp = _utc_stamp(last)
        body = {
            "servers": {self._settings.server_name: {"last_activity": stamp}},
            "last_activity": stamp,
        }
        try:
            self._post(self._settings.activity_url, self._settings.api_token, body=body)
        except HubRefused as error:
            log.warning("the hub refused our activity report (%s): %s", error.status, error)
            return False
        self._sent = last
        return True

    def _run(self) -> None:
        while not self._stop.wait(self._settings.activity_interval):
            self.report()


class HubLogin:
    """The gate in front of the dashboard's server in the lean mode (app.access ``gate``).

    ``wrap`` composes our check in front of the dashboard's own routes;
    ``wrap_handler`` counts the learner's websocket messages as activity.
    """

    def __init__(
        self,
        settings: HubSettings,
        ask_hub: AskHub = hub_request,
        signer: Signer | None = None,
    ) -> None:
        self.settings = settings
        self._users = HubUsers(settings.api_url, ask_hub)
        self._signer = signer or Signer()
        self.activity = Activity(settings, ask_hub)
        self.installed = False
        self.refused = 0
        self.cookie_name = settings.client_id  # as HubOAuth names it
        self.state_cookie_name = settings.client_id + "-oauth-state"
        try:
            self._hub_version: str | None = metadata.version("jupyterhub")
        except metadata.PackageNotFoundError:
            self._hub_version = None

    async def user_for_token(self, token: str) -> dict[str, Any] | None:
        """The hub's user model for a token (with its scopes), or None if it knows none."""
        return await self._users.user_for_token(token)

    def may_access(self, user: dict[str, Any] | None) -> bool:
        return user is not None and grants(
            set(user.get("scopes") or ()), self.settings.access_scopes
        )

    # -- the HTTP layer ------------------------------------------------------------------

    def wrap(self, inner: ProcessRequest | None) -> AsyncProcessRequest:
        self.installed = True
        self.activity.start()

        async def process_request(
            connection: ServerConnection, request: Request
        ) -> Response | None:
            try:
                return await self._process(connection, request, inner)
            except HubRefused as error:
                log.warning("asking the hub failed: %s %s", error.status, error)
                return _text(http.HTTPStatus.BAD_GATEWAY, f"Could not ask the hub: {error}\n")
            except Exception:  # viser's server would hang up silently (it mutes these logs)
                log.exception("serving %s failed", request.path.partition("?")[0])
                return _text(http.HTTPStatus.INTERNAL_SERVER_ERROR, "The dashboard failed here.\n")

        return process_request

    async def _process(
        self, connection: ServerConnection, request: Request, inner: ProcessRequest | None
    ) -> Response | None:
        prefix = self.settings.prefix
        raw_path, _, query = request.path.partition("?")
        is_socket = request.headers.get("Upgrade", "").lower() == "websocket"
        if raw_path == prefix.rstrip("/"):  # viser's client cuts the slash off its socket URL
            if not is_socket:
                return _redirect(prefix + (f"?{query}" if query else ""))
            raw_path = prefix
        if not raw_path.startswith(prefix):
            return _text(http.HTTPStatus.NOT_FOUND, f"Not found: this server serves {prefix}\n")
        rest = raw_path[len(prefix) :]
        if rest == "api" and not is_socket:  # the hub's "is it up?" probe, before any login
            return self._status()
        if rest == "oauth_callback" and not is_socket:
            return await self._callback(request, query)

        token, from_cookie = _header_token(request), False
        if token is None:
            token = self._signer.unsign(
                self.cookie_name, _cookie(request, self.cookie_name), COOKIE_MAX_AGE_SEC
            )
            from_cookie = token is not None
        user = await self.user_for_token(token) if token else None
        if user is None:
            self.refused += 1
            if is_socket or _header_token(request) is not None:
                return _text(
                    http.HTTPStatus.UNAUTHORIZED,
                    "Log in through the hub first: open this Classroom's page.\n",
                )
            return self._login_redirect(request)
        if not self.may_access(user):
            self.refused += 1
            return _text(
                http.HTTPStatus.FORBIDDEN,
                f"{user.get('name', 'this token')} may not open {self.settings.user}'s "
                "ROS 2 Classroom.\n",
            )
        if from_cookie and not same_origin(request):
            self.refused += 1
            return _text(http.HTTPStatus.FORBIDDEN, "Cross-site request.\n")
        self.activity.touch()
        request.path = "/" + rest + (f"?{query}" if query else "")  # as the routes expect
        response = inner(connection, request) if inner is not None else None
        if response is not None and "Connection" not in response.headers:
            # websockets closes the connection after every HTTP answer. Unless the answer
            # says so, the hub's proxy keeps the socket for its next request (a websocket's
            # upgrade, say), which then meets a closed socket: "503 socket hang up".
            response.headers["Connection"] = "close"
        return response

    def _status(self) -> Response:
        body = json.dumps({"server": "ros2-classroom", "user": self.settings.user}).encode()
        headers = [("Content-Type", "application/json")]
        if self._hub_version:  # the hub compares it with its own, as for jupyterhub-singleuser
            headers.append(("X-JupyterHub-Version", self._hub_version))
        return _response(http.HTTPStatus.OK, headers, body)

    def _login_redirect(self, request: Request) -> Response:
        state = new_state()
        next_url = request.path if request.path.startswith(self.settings.prefix) else "/"
        cookie = self._signer.sign(self.state_cookie_name, json.dumps([state, next_url]))
        query = authorize_query(self.settings.client_id, self.settings.callback_url, state)
        return _redirect(
            f"{self.settings.authorize_url}?{query}",
            self._set_cookie(self.state_cookie_name, cookie, request, max_age=STATE_MAX_AGE_SEC),
        )

    async def _callback(self, request: Request, query: str) -> Response:
        args = {k: v[0] for k, v in urllib.parse.parse_qs(query).items()}
        if "error" in args:
            reason = args.get("error_description") or args["error"]
            return _text(http.HTTPStatus.FORBIDDEN, f"The hub did not log you in: {reason}\n")
        saved = self._signer.unsign(
            self.state_cookie_name, _cookie(request, self.state_cookie_name), STATE_MAX_AGE_SEC
        )
        try:
            state, next_url = json.loads(saved) if saved else (None, None)
        except ValueError:
            state, next_url = None, None
        if not same_state(state, args.get("state", "")):
            return _text(
                http.HTTPStatus.BAD_REQUEST,
                "This login does not match the one this browser started (OAuth state): "
                "open the Classroom's page again.\n",
            )
        if not args.get("code"):
            return _text(http.HTTPStatus.BAD_REQUEST, "The hub sent no OAuth code.\n")
        try:
            token = await self._users.token_for_code(
                args["code"],
                client_id=self.settings.client_id,
                client_secret=self.settings.api_token,
                redirect_uri=self.settings.callback_url,
            )
        except HubRefused as error:
            if error.status >= 500:
                raise
            return _text(http.HTTPStatus.FORBIDDEN, f"The hub refused the OAuth code: {error}\n")
        user = await self.user_for_token(token)
        if not self.may_access(user):
            name = user.get("name", "this login") if user else "this login"
            return _text(
                http.HTTPStatus.FORBIDDEN,
                f"{name} may not open {self.settings.user}'s ROS 2 Classroom.\n",
            )
        target = str(next_url)
        if not target.startswith(self.settings.prefix):  # never a redirect off this server
            target = self.settings.prefix
        return _redirect(
            target,
            self._set_cookie(self.cookie_name, self._signer.sign(self.cookie_name, token), request),
            self._set_cookie(self.state_cookie_name, "", request, max_age=0),
        )

    def _set_cookie(
        self, name: str, value: str, request: Request, max_age: int | None = None
    ) -> str:
        parts = [f"{name}={value}", f"Path={self.settings.prefix}", "HttpOnly", "SameSite=Lax"]
        if max_age is not None:
            parts.append(f"Max-Age={max_age}")
        forwarded = request.headers.get("X-Forwarded-Proto", "").split(",")[0].strip().lower()
        if self.settings.secure_cookies or forwarded == "https":
            parts.append("Secure")
        return "; ".join(parts)

    # -- the websocket: the learner's messages are activity --------------------------

    def wrap_handler(self, inner: Handler) -> Handler:
        activity = self.activity

        async def handler(connection: ServerConnection) -> None:
            receive = connection.recv

            async def recv(*args: bool | None, **kwargs: bool | None) -> Any:
                message = await receive(*args, **kwargs)
                activity.touch()
                return message

            connection.recv = recv  # type: ignore[method-assign]
            await inner(connection)

        return handler

    def close(self) -> None:
        self.activity.stop()


def _header_token(request: Request) -> str | None:
    return header_token(request.headers.get("Authorization", ""))


def _cookie(request: Request, name: str) -> str | None:
    """One cookie's value; other cookies, however odd, never hide it (unlike SimpleCookie)."""
    for header in request.headers.get_all("Cookie"):
        for part in header.split(";"):
            key, sep, value = part.strip().partition("=")
            if sep and key == name:
                return value.strip().strip('"')
    return None


def _response(status: http.HTTPStatus, headers: list[tuple[str, str]], body: bytes) -> Response:
    all_headers = Headers(
        [
            ("Date", formatdate(usegmt=True)),
            ("Connection", "close"),
            ("Content-Length", str(len(body))),
            ("Cache-Control", "no-store"),
            *headers,
        ]
    )
    return Response(status.value, status.phrase, all_headers, body)


def _text(status: http.HTTPStatus, text: str) -> Response:
    return _response(status, [("Content-Type", "text/plain; charset=utf-8")], text.encode())


def _redirect(location: str, *cookies: str) -> Response:
    return _response(
        http.HTTPStatus.FOUND,
        [("Location", location), *(("Set-Cookie", c) for c in cookies)],
        b"",
    )
