"""From a checked launch to a hub login: a one-time ticket the hub redeems with us.

The service that checks launches is not the hub, and only the hub can log a
browser in. So a good launch ends in a redirect to the hub's handoff page
with a ticket: a random string, good once, for a minute. The hub's
authenticator (app/hub/lti_login.py) posts it back to the service, learns
whom to log in and where to send them, and the ticket is spent. A ticket
that leaks later (browser history, a log) opens nothing.
"""

from __future__ import annotations

import secrets
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

TICKET_LIFE_SEC = 60.0


class HandoffRefused(Exception):
    """The ticket is unknown, spent or too old; the message says which, for the log."""


@dataclass(frozen=True)
class Handoff:
    name: str  # the hub user to log in
    next_url: str  # a path on the hub: the learner's server, or the teacher's page
    teacher: bool  # the LMS gave this person a teaching role in the launch


class HandoffTickets:
    def __init__(
        self, *, life_sec: float = TICKET_LIFE_SEC, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self._life, self._clock = life_sec, clock
        self._open: dict[str, tuple[Handoff, float]] = {}
        self._lock = threading.Lock()

    def issue(self, handoff: Handoff) -> str:
        ticket = secrets.token_urlsafe(32)
        with self._lock:
            now = self._clock()
            self._open = {t: v for t, v in self._open.items() if now - v[1] <= self._life}
            self._open[ticket] = (handoff, now)
        return ticket

    def redeem(self, ticket: str) -> Handoff:
        with self._lock:
            found = self._open.pop(ticket, None)
        if found is None:
            raise HandoffRefused("the launch ticket is unknown or was already used")
        if self._clock() - found[1] > self._life:
            raise HandoffRefused(f"the launch ticket is older than {self._life:.0f} s")
        return found[0]
