"""The few HTTP calls LTI needs, over urllib, with one answer type for every status.

A platform that cannot be reached (refused connection, DNS failure,
timeout) raises ``Unreachable``; any HTTP answer, 4xx and 5xx included, is
returned for the caller to judge, since what a status means differs between
the token endpoint, the scores endpoint and a JWKS.
"""

from __future__ import annotations

import json
import urllib.error
import urllib.request
from collections.abc import Mapping
from dataclasses import dataclass, field

TIMEOUT_SEC = 10.0
MAX_BODY_BYTES = 1 << 20  # a JWKS or a token answer is a few KB; anything huge is garbage


class Unreachable(Exception):
    """No HTTP answer at all; the message says why."""


@dataclass(frozen=True)
class Answer:
    status: int
    body: bytes
    headers: Mapping[str, str] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return 200 <= self.status < 300

    def json(self) -> object:
        """The body as JSON; ``ValueError`` when it is not."""
        return json.loads(self.body.decode("utf-8"))

    def reason(self, limit: int = 300) -> str:
        """The body as a short line for a log or a teacher's page."""
        text = self.body.decode("utf-8", "replace").strip().replace("\n", " ")
        return f"HTTP {self.status}" + (f": {text[:limit]}" if text else "")


def call(
    method: str,
    url: str,
    *,
    data: bytes | None = None,
    headers: Mapping[str, str] | None = None,
    timeout: float = TIMEOUT_SEC,
) -> Answer:
    request = urllib.request.Request(url, data=data, method=method, headers=dict(headers or {}))
    try:
        with urllib.request.urlopen(request, timeout=timeout) as response:
            return Answer(response.status, response.read(MAX_BODY_BYTES), dict(response.headers))
    except urllib.error.HTTPError as error:
        try:
            return Answer(error.code, error.read(MAX_BODY_BYTES), dict(error.headers or {}))
        finally:
            error.close()
    except (urllib.error.URLError, TimeoutError, OSError) as error:
        reason = getattr(error, "reason", None) or error
        raise Unreachable(f"{url} could not be reached ({reason})") from None
