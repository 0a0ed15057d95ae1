"""The hub's OAuth for a JupyterHub service on tornado: the teacher's service logs teachers in.

What ``jupyterhub.services.auth`` (``HubAuth``, ``HubOAuth``,
``HubOAuthenticated``, ``HubOAuthCallbackHandler``) does for a service, on
the calls of app/hub/hub_api.py, which the lean learner's dashboard shares
(its own HTTP layer is app/hub/singleuser_auth.py):

- A request carries a hub token in an ``Authorization: token`` header (an
  API client, a learner's dashboard reporting) or in our signed, HttpOnly
  cookie (a teacher's browser after logging in).
- A page for teachers (``HubLoginRequired``) lets in only users whose token
  holds one of the service's access scopes (``JUPYTERHUB_OAUTH_ACCESS_SCOPES``:
  admins, and the teachers' group through its role); anyone else gets 403.
  A browser without a login is sent to the hub's authorize URL with a random
  ``state``, kept in a signed cookie with the page to come back to.
- ``OAuthCallbackHandler`` (``<prefix>oauth_callback``) checks that state,
  exchanges the hub's code for a token and keeps the token in the cookie.
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from tornado import web

from app.hub.hub_api import (
    CACHE_SEC,
    STATE_MAX_AGE_SEC,
    AskHub,
    HubRefused,
    HubUsers,
    authorize_query,
    authorize_url,
    grants,
    header_token,
    hub_request,
    new_state,
    same_state,
)

log = logging.getLogger(__name__)

STATE_MAX_AGE_DAYS = STATE_MAX_AGE_SEC / 86400  # tornado's signed cookies count in days


class ServiceSettingsError(ValueError):
    """The environment the hub gives its managed services is missing something."""


@dataclass(frozen=True)
class ServiceSettings:
    """What the hub tells a managed service with OAuth, through the environment."""

    api_url: str  # the hub's API, as this service reaches it
    api_token: str  # the service's token; also its OAuth client's secret
    client_id: str
    callback_url: str
    authorize_url: str  # where browsers are sent to log in
    access_scopes: frozenset[str]
    prefix: str  # /services/<name>/: our cookies' path

    @classmethod
    def from_env(cls, service_name: str, env: Mapping[str, str] | None = None) -> ServiceSettings:
        env = dict(os.environ if env is None else env)
        needed = ("JUPYTERHUB_API_URL", "JUPYTERHUB_API_TOKEN")
        missing = [name for name in needed if not env.get(name)]
        if missing:
            raise ServiceSettingsError(
                f"the teacher service runs as a JupyterHub service (missing {', '.join(missing)})"
            )
        prefix = env.get("JUPYTERHUB_SERVICE_PREFIX") or f"/services/{service_name}/"
        try:
            scopes = json.loads(env.get("JUPYTERHUB_OAUTH_ACCESS_SCOPES") or "[]")
        except ValueError as error:
            raise ServiceSettingsError(
                f"JUPYTERHUB_OAUTH_ACCESS_SCOPES is not JSON: {error}"
            ) from None
        if not isinstance(scopes, list) or not all(isinstance(x, str) for x in scopes):
            raise ServiceSettingsError("JUPYTERHUB_OAUTH_ACCESS_SCOPES must be a list of scopes")
        return cls(
            api_url=env["JUPYTERHUB_API_URL"].rstrip("/"),
            api_token=env["JUPYTERHUB_API_TOKEN"],
            client_id=env.get("JUPYTERHUB_CLIENT_ID") or f"service-{service_name}",
            callback_url=env.get("JUPYTERHUB_OAUTH_CALLBACK_URL") or prefix + "oauth_callback",
            authorize_url=authorize_url(env),
            # The hub's default for a service, as HubOAuth takes it when the hub names none.
            access_scopes=frozenset(scopes or [f"access:services!service={service_name}"]),
            prefix=prefix,
        )


class ServiceAuth:
    """Who a request is, as the hub says, and whether the hub lets them into this service."""

    def __init__(
        self, settings: ServiceSettings, ask_hub: AskHub = hub_request, cache_sec: float = CACHE_SEC
    ) -> None:
        self.settings = settings
        self.users = HubUsers(settings.api_url, ask_hub, cache_sec)
        self.cookie_name = settings.client_id  # as HubOAuth names it
        self.state_cookie_name = settings.client_id + "-oauth-state"

    async def user_for_token(self, token: str) -> dict[str, Any] | None:
        return await self.users.user_for_token(token)

    def may_access(self, user: Mapping[str, Any]) -> bool:
        return grants(set(user.get("scopes") or ()), self.settings.access_scopes)

    def token_of(self, handler: web.RequestHandler) -> str | None:
        """The request's hub token: its Authorization header, else our login cookie."""
        token = header_token(handler.request.headers.get("Authorization", ""))
        if token is not None:
            return token
        cookie = handler.get_signed_cookie(self.cookie_name)
        return cookie.decode() if cookie else None

    def login_url(self, handler: web.RequestHandler) -> str:
        """The hub's authorize URL for this browser, its state kept in a signed cookie."""
        state = new_state()
        handler.set_signed_cookie(
            self.state_cookie_name,
            json.dumps([state, handler.request.uri or self.settings.prefix]),
            expires_days=STATE_MAX_AGE_DAYS,
            **self.cookie_options(handler),
        )
        query = authorize_query(self.settings.client_id, self.settings.callback_url, state)
        return f"{self.settings.authorize_url}?{query}"

    def cookie_options(self, handler: web.RequestHandler) -> dict[str, Any]:
        options: dict[str, Any] = {"path": self.settings.prefix, "httponly": True}
        forwarded = handler.request.headers.get("X-Forwarded-Proto", "").split(",")[0].strip()
        if handler.request.protocol == "https" or forwarded.lower() == "https":
            options["secure"] = True
        return options


class HubLoginRequired(web.RequestHandler):
    """A mixin for pages only the hub's users granted this service may open.

    It comes first in a handler's bases. Its ``prepare`` asks the hub whose
    token the request carries (the answer cached) and sets ``current_user``,
    so ``@web.authenticated`` sends a browser without a login to the hub,
    and a user the hub does not grant this service gets 403.
    """

    @property
    def service_auth(self) -> ServiceAuth:
        auth: ServiceAuth = self.settings["service_auth"]
        return auth

    async def prepare(self) -> None:
        auth = self.service_auth
        token = auth.token_of(self)
        try:
            user = await auth.user_for_token(token) if token else None
        except HubRefused as error:
            raise web.HTTPError(502, f"could not ask the hub who you are: {error}") from None
        if user is not None and not auth.may_access(user):
            name = user.get("name", "this token")
            raise web.HTTPError(403, f"{name} is not allowed here: this page is for teachers")
        self.current_user = user

    def get_login_url(self) -> str:
        return self.service_auth.login_url(self)


class OAuthCallbackHandler(web.RequestHandler):
    """``<prefix>oauth_callback``: the hub sends a browser back here with a code."""

    def write_error(self, status_code: int, **kwargs: Any) -> None:
        error = kwargs.get("exc_info", (None, None, None))[1]
        reason = error.log_message if isinstance(error, web.HTTPError) else None
        self.set_header("Content-Type", "text/plain; charset=utf-8")
        self.finish(f"{status_code}: {reason or self._reason}\n")

    async def get(self) -> None:
        auth: ServiceAuth = self.settings["service_auth"]
        if self.get_argument("error", ""):
            reason = self.get_argument("error_description", "") or self.get_argument("error")
            raise web.HTTPError(403, f"the hub did not log you in: {reason}")
        saved = self.get_signed_cookie(auth.state_cookie_name, max_age_days=STATE_MAX_AGE_DAYS)
        try:
            state, next_url = json.loads(saved) if saved else (None, None)
        except ValueError:
            state, next_url = None, None
        if not same_state(state, self.get_argument("state", "")):
            raise web.HTTPError(
                400,
                "this login does not match the one this browser started (OAuth state): "
                "open the teacher's page again",
            )
        code = self.get_argument("code", "")
        if not code:
            raise web.HTTPError(400, "the hub sent no OAuth code")
        try:
            token = await auth.users.token_for_code(
                code,
                client_id=auth.settings.client_id,
                client_secret=auth.settings.api_token,
                redirect_uri=auth.settings.callback_url,
            )
            user = await auth.user_for_token(token)
        except HubRefused as error:
            status = 502 if error.status >= 500 else 403
            raise web.HTTPError(status, f"the hub refused the login: {error}") from None
        if user is None or not auth.may_access(user):
            name = user.get("name", "this login") if user else "this login"
            raise web.HTTPError(403, f"{name} is not allowed here: this page is for teachers")
        log.info("teacher %s logged in", user.get("name"))
        options = auth.cookie_options(self)
        self.clear_cookie(auth.state_cookie_name, path=auth.settings.prefix)
        self.set_signed_cookie(auth.cookie_name, token, **options)
        target = str(next_url or "")
        if not target.startswith(auth.settings.prefix):  # never a redirect off this service
            target = auth.settings.prefix
        self.redirect(target)
