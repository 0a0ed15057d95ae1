"""A platform's public keys (its JWKS), fetched over HTTP and kept for a while.

Platforms rotate keys by publishing the new one before signing with it, so
an unknown ``kid`` means "fetch again": once, and not more often than every
few seconds, so forged tokens with made-up kids cannot make us hammer the LMS.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import jwt

from app.lti import transport
from app.lti.rejection import LaunchRejected

MAX_AGE_SEC = 3600.0
REFETCH_GAP_SEC = 5.0


class PlatformKeys:
    def __init__(
        self,
        jwks_url: str,
        *,
        max_age_sec: float = MAX_AGE_SEC,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.jwks_url = jwks_url
        self._max_age, self._clock = max_age_sec, clock
        self._keys: dict[str | None, jwt.PyJWK] = {}
        self._fetched_at: float | None = None
        self._lock = threading.Lock()

    def key_for(self, kid: str | None) -> jwt.PyJWK:
        """The platform's key named ``kid`` (or its only key, for a token with no kid)."""
        with self._lock:
            now = self._clock()
            stale = self._fetched_at is None or now - self._fetched_at > self._max_age
            if stale:
                self._fetch(now)
            key = self._pick(kid)
            if key is None and not stale and now - (self._fetched_at or 0) >= REFETCH_GAP_SEC:
                self._fetch(now)  # the platform may have rotated its key since
                key = self._pick(kid)
            if key is None:
                raise LaunchRejected(
                    f"the platform's key set at {self.jwks_url} has no key with kid {kid!r}: "
                    "the id_token was not signed by this platform"
                )
            return key

    def _pick(self, kid: str | None) -> jwt.PyJWK | None:
        if kid is None and len(self._keys) == 1:
            return next(iter(self._keys.values()))
        return self._keys.get(kid)

    def _fetch(self, now: float) -> None:
        try:
            answer = transport.call("GET", self.jwks_url, headers={"Accept": "application/json"})
            if not answer.ok:
                raise LaunchRejected(
                    f"the platform's key set at {self.jwks_url} answered {answer.reason()}"
                )
            document = answer.json()
            if not isinstance(document, dict):
                raise ValueError("not a JSON object")
            key_set = jwt.PyJWKSet.from_dict(document)
        except transport.Unreachable as error:
            raise LaunchRejected(f"the platform's key set could not be fetched: {error}") from None
        except (ValueError, jwt.PyJWTError) as error:
            raise LaunchRejected(
                f"the platform's key set at {self.jwks_url} is not a usable JWKS ({error})"
            ) from None
        self._keys = {key.key_id: key for key in key_set.keys}
        self._fetched_at = now
