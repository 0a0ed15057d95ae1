"""The login step's state and nonce pairs, each accepted by one launch only.

The login step issues a pair; the launch that follows must bring the same
state back (in the form post) and the same nonce inside the signed id_token.
A redeemed nonce is remembered for a while after, so a replayed id_token is
named as a replay rather than as an unknown login.

Kept in memory: a restart between the two steps (a second or so apart)
only makes that learner click the link again.
"""

from __future__ import annotations

import secrets
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from app.lti.rejection import LaunchRejected

LOGIN_TTL_SEC = 600.0  # a login the browser does not finish within this is forgotten
USED_TTL_SEC = 7200.0  # longer than any platform's id_token lives (Canvas: one hour)


@dataclass(frozen=True)
class LoginPair:
    state: str
    nonce: str


class NonceStore:
    def __init__(
        self,
        *,
        login_ttl_sec: float = LOGIN_TTL_SEC,
        used_ttl_sec: float = USED_TTL_SEC,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._login_ttl, self._used_ttl, self._clock = login_ttl_sec, used_ttl_sec, clock
        self._issued: dict[str, tuple[str, float]] = {}  # state -> (nonce, issued at)
        self._used: dict[str, float] = {}  # nonce -> redeemed at
        self._lock = threading.Lock()

    def issue(self) -> LoginPair:
        pair = LoginPair(secrets.token_urlsafe(24), secrets.token_urlsafe(24))
        with self._lock:
            self._forget_old(self._clock())
            self._issued[pair.state] = (pair.nonce, self._clock())
        return pair

    def redeem(self, state: str, nonce: str) -> None:
        """Accept this pair once; raise ``LaunchRejected`` saying why otherwise."""
        with self._lock:
            now = self._clock()
            self._forget_old(now)
            if nonce in self._used:
                raise LaunchRejected(
                    "the id_token's nonce was already used: this launch is a replay and is "
                    "accepted only once"
                )
            issued = self._issued.get(state)
            if issued is None:
                raise LaunchRejected(
                    "the launch's state was not issued by this tool's login step, or that login "
                    "is more than a few minutes old: start again from the LMS"
                )
            if issued[0] != nonce:
                raise LaunchRejected(
                    "the id_token's nonce is not the one this tool's login step issued with "
                    "that state"
                )
            del self._issued[state]
            self._used[nonce] = now

    def _forget_old(self, now: float) -> None:
        self._issued = {s: v for s, v in self._issued.items() if now - v[1] <= self._login_ttl}
        self._used = {n: t for n, t in self._used.items() if now - t <= self._used_ttl}
