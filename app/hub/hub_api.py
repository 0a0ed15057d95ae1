"""Asking JupyterHub's API, as its servers and services do: whose token, which scopes, OAuth codes.

What both of our hub clients share: the lean mode's learner dashboard
(app/hub/singleuser_auth.py, on viser's websockets server) and the teacher's
service (app/hub/service_auth.py, on tornado). They do the steps of
``jupyterhub.services.auth`` with the standard library only: importing
jupyterhub's own client brings SQLAlchemy and costs a process about 36 MB
(issue 43: a learner's dashboard, and the class's one teacher service).
"""

from __future__ import annotations

import asyncio
import base64
import hashlib
import hmac
import json
import secrets
import time
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

CACHE_SEC = 300.0  # how long the hub's answer about a token holds (HubAuth's default)
HUB_TIMEOUT_SEC = 10.0
STATE_MAX_AGE_SEC = 600  # an OAuth round trip never takes longer than this

AskHub = Callable[..., object]


def grants(held: set[str] | frozenset[str], required: frozenset[str]) -> bool:
    """Whether scopes the hub lists for a token cover one of ``required``.

    As ``jupyterhub.services.auth.check_scopes``: an unfiltered scope covers
    all its filters, ``!user=x`` covers that user's servers; group filters
    are not resolved here (the hub resolves them when it issues OAuth tokens
    for a server, so a learner's own token holds the server's scope itself).
    """
    for want in required:
        base, _, wanted = want.partition("!")
        for have in held:
            have_base, _, filt = have.partition("!")
            if have_base != base:
                continue
            if not filt or filt == wanted:
                return True
            if filt.startswith("user=") and wanted.startswith("server="):
                if wanted[len("server=") :].split("/", 1)[0] == filt[len("user=") :]:
                    return True
    return False


class Signer:
    """Values we hand to a browser and must get back unchanged (HMAC-SHA256, dated)."""

    def __init__(self, secret: bytes | None = None) -> None:
        # A fresh secret per process: a restarted server only sends browsers round the hub again.
        self._secret = secret or secrets.token_bytes(32)

    def _mac(self, name: str, payload: str) -> str:
        return hmac.new(self._secret, f"{name}|{payload}".encode(), hashlib.sha256).hexdigest()

    def sign(self, name: str, value: str, now: float | None = None) -> str:
        data = base64.urlsafe_b64encode(value.encode()).decode().rstrip("=")
        payload = f"{data}|{int(time.time() if now is None else now)}"
        return f"{payload}|{self._mac(name, payload)}"

    def unsign(self, name: str, signed: str | None, max_age: float) -> str | None:
        """The value, or None if it was changed, made for another name, or is too old."""
        if not signed or signed.count("|") != 2:
            return None
        payload, _, mac = signed.rpartition("|")
        if not hmac.compare_digest(mac, self._mac(name, payload)):
            return None
        data, _, stamp = payload.partition("|")
        if not stamp.isdigit() or time.time() - int(stamp) > max_age:
            return None
        try:
            return base64.urlsafe_b64decode(data + "=" * (-len(data) % 4)).decode()
        except (ValueError, UnicodeDecodeError):
            return None


class HubRefused(Exception):
    """The hub could not be asked, or answered with an error (status and reason)."""

    def __init__(self, status: int, reason: str) -> None:
        super().__init__(reason)
        self.status = status


def hub_request(
    url: str, token: str, form: dict[str, str] | None = None, body: object = None
) -> object:
    """One blocking call to the hub's API; JSON answer. Raises HubRefused."""
    headers = {"Authorization": f"token {token}"}
    data = None
    if form is not None:
        data = urllib.parse.urlencode(form).encode()
        headers["Content-Type"] = "application/x-www-form-urlencoded"
    elif body is not None:
        data = json.dumps(body).encode()
        headers["Content-Type"] = "application/json"
    request = urllib.request.Request(url, data, headers, method="POST" if data else "GET")
    try:
        with urllib.request.urlopen(request, timeout=HUB_TIMEOUT_SEC) as answer:
            text = answer.read()
    except urllib.error.HTTPError as error:
        raise HubRefused(error.code, error.read()[:300].decode(errors="replace")) from None
    except OSError as error:
        raise HubRefused(502, f"the hub's API at {url} did not answer: {error}") from None
    return json.loads(text) if text else None


@dataclass
class _Cached:
    user: dict[str, Any] | None
    expires: float


class HubUsers:
    """Whose token is whose (with the token's scopes), as the hub answers, cached.

    The blocking call runs in a worker thread, so the caller's event loop
    (viser's or tornado's) never waits on the hub.
    """

    def __init__(self, api_url: str, ask_hub: AskHub = hub_request, cache_sec: float = CACHE_SEC):
        self.api_url = api_url.rstrip("/")
        self._ask_hub = ask_hub
        self._cache_sec = cache_sec
        self._cache: dict[str, _Cached] = {}  # sha256(token) -> the hub's answer

    async def call(self, *args: object, **kwargs: object) -> object:
        return await asyncio.to_thread(self._ask_hub, *args, **kwargs)

    async def user_for_token(self, token: str) -> dict[str, Any] | None:
        """The hub's user model for a token (with its scopes), or None if it knows none."""
        key = hashlib.sha256(token.encode()).hexdigest()
        cached = self._cache.get(key)
        now = time.monotonic()
        if cached is not None and cached.expires > now:
            return cached.user
        try:
            user = await self.call(f"{self.api_url}/user", token)
        except HubRefused as error:
            if error.status not in (401, 403, 404):
                raise
            user = None
        if len(self._cache) > 1000:  # never grows without bound
            self._cache = {k: v for k, v in self._cache.items() if v.expires > now}
        self._cache[key] = _Cached(user if isinstance(user, dict) else None, now + self._cache_sec)
        return self._cache[key].user

    async def token_for_code(
        self, code: str, *, client_id: str, client_secret: str, redirect_uri: str
    ) -> str:
        """OAuth's last step: the hub's token for the code it sent the browser back with.

        Raises HubRefused (a 4xx: the hub refused the code; 502: no token in its answer).
        """
        answer = await self.call(
            f"{self.api_url}/oauth2/token",
            client_secret,
            form={
                "client_id": client_id,
                "client_secret": client_secret,
                "grant_type": "authorization_code",
                "code": code,
                "redirect_uri": redirect_uri,
            },
        )
        token = answer.get("access_token") if isinstance(answer, dict) else None
        if not isinstance(token, str) or not token:
            raise HubRefused(502, "The hub's token answer held no token.")
        return token


def header_token(authorization: str) -> str | None:
    """The token of an ``Authorization: token <t>`` (or ``bearer``) header, else None."""
    scheme, _, token = authorization.strip().partition(" ")
    if scheme.lower() in ("token", "bearer") and token.strip():
        return token.strip()
    return None


def new_state() -> str:
    """An OAuth ``state``: random, url-safe."""
    return secrets.token_urlsafe(16)


def same_state(saved: object, got: str) -> bool:
    """Whether the ``state`` the hub sent back is the one this browser started with."""
    return bool(saved) and secrets.compare_digest(str(saved).encode(), got.encode())


def authorize_url(env: dict[str, str]) -> str:
    """Where a browser logs in: the hub's authorize URL, on the hub's own host if it has one."""
    hub_prefix = env.get("JUPYTERHUB_BASE_URL", "/").rstrip("/") + "/hub/"
    return env.get("JUPYTERHUB_HOST", "") + hub_prefix + "api/oauth2/authorize"


def authorize_query(client_id: str, redirect_uri: str, state: str) -> str:
    return urllib.parse.urlencode(
        {
            "client_id": client_id,
            "redirect_uri": redirect_uri,
            "response_type": "code",
            "state": state,
        }
    )
