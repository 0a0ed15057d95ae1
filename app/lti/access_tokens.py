"""OAuth 2 access tokens for grade passback, by the client_credentials grant.

We prove who we are with a JWT client assertion signed by the tool key
(RFC 7523, as LTI's security framework asks), and keep each token until
shortly before it expires: 200 scores need one token request, not 200.
"""

from __future__ import annotations

import secrets
import threading
import time
import urllib.parse
from collections.abc import Callable

from app.lti import transport
from app.lti.keys import ToolKeys
from app.lti.registration import PlatformRegistration

ASSERTION_TYPE = "urn:ietf:params:oauth:client-assertion-type:jwt-bearer"
ASSERTION_LIFE_SEC = 300
EXPIRY_MARGIN_SEC = 30.0  # renew a little early: a token may expire while a POST is on its way
DEFAULT_LIFE_SEC = 3600.0  # when the platform does not say (expires_in is optional)


class TokenUnavailable(Exception):
    """The token endpoint gave no usable token; the message says what it answered."""


class AccessTokens:
    def __init__(self, keys: ToolKeys, *, clock: Callable[[], float] = time.time) -> None:
        self._keys, self._clock = keys, clock
        self._cache: dict[tuple[str, str, str], tuple[str, float]] = {}  # -> (token, expires)
        self._lock = threading.Lock()
        self.requests_made = 0  # for the outbox page and the benchmark

    def token(self, registration: PlatformRegistration, scopes: tuple[str, ...]) -> str:
        scope = " ".join(sorted(scopes))
        key = (registration.issuer, registration.client_id, scope)
        with self._lock:
            cached = self._cache.get(key)
            if cached is not None and self._clock() < cached[1]:
                return cached[0]
            token, expires = self._request(registration, scope)
            self._cache[key] = (token, expires)
            return token

    def forget(self, registration: PlatformRegistration) -> None:
        """Drop tokens the platform no longer accepts (it answered 401)."""
        with self._lock:
            for key in [
                k for k in self._cache if k[:2] == (registration.issuer, registration.client_id)
            ]:
                del self._cache[key]

    def _assertion(self, registration: PlatformRegistration) -> str:
        now = int(self._clock())
        return self._keys.sign(
            {
                "iss": registration.client_id,
                "sub": registration.client_id,
                "aud": registration.assertion_audience,
                "iat": now,
                "exp": now + ASSERTION_LIFE_SEC,
                "jti": secrets.token_urlsafe(16),  # platforms may refuse a reused assertion
            }
        )

    def _request(self, registration: PlatformRegistration, scope: str) -> tuple[str, float]:
        form = urllib.parse.urlencode(
            {
                "grant_type": "client_credentials",
                "client_assertion_type": ASSERTION_TYPE,
                "client_assertion": self._assertion(registration),
                "scope": scope,
            }
        ).encode("ascii")
        self.requests_made += 1
        try:
            answer = transport.call(
                "POST",
                registration.auth_token_url,
                data=form,
                headers={
                    "Content-Type": "application/x-www-form-urlencoded",
                    "Accept": "application/json",
                },
            )
        except transport.Unreachable as error:
            raise TokenUnavailable(f"the token endpoint: {error}") from None
        if not answer.ok:
            raise TokenUnavailable(f"the token endpoint refused us: {answer.reason()}")
        try:
            body = answer.json()
        except ValueError:
            raise TokenUnavailable(
                f"the token endpoint answered no JSON: {answer.reason()}"
            ) from None
        token = body.get("access_token") if isinstance(body, dict) else None
        if not isinstance(token, str) or not token:
            raise TokenUnavailable(
                f"the token endpoint answered no access_token: {answer.reason()}"
            )
        life = body.get("expires_in", DEFAULT_LIFE_SEC) if isinstance(body, dict) else 0
        life = float(life) if isinstance(life, (int, float)) else DEFAULT_LIFE_SEC
        return token, self._clock() + max(0.0, life - EXPIRY_MARGIN_SEC)
