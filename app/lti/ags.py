"""Posting one score to an AGS line item, and saying what became of it.

The outcome sorts every answer into three kinds the outbox acts on:
delivered; worth retrying later (platform down, slow, 5xx, 429, a token
problem); or refused for good with the platform's reason (any other 4xx).
A 409 means the platform already holds this result (Moodle answers it for a
repeated timestamp, e.g. when we resend after a crash): delivered, not lost.
"""

from __future__ import annotations

import json
import urllib.parse
from dataclasses import dataclass
from typing import Literal

from app.lti import transport
from app.lti.access_tokens import AccessTokens, TokenUnavailable
from app.lti.claims import SCORE_SCOPE
from app.lti.registration import Registrations
from app.lti.score import Score

SCORE_MEDIA_TYPE = "application/vnd.ims.lis.v1.score+json"


@dataclass(frozen=True)
class PostOutcome:
    kind: Literal["delivered", "retry", "refused"]
    reason: str = ""
    retry_after_sec: float | None = None  # the platform's Retry-After, when it gave one
    platform_down: bool = False  # no answer at all: other posts to it will fail too


def scores_url(lineitem: str) -> str:
    """``<lineitem>/scores``, the path appended before any query string (as AGS says)."""
    parts = urllib.parse.urlsplit(lineitem)
    return urllib.parse.urlunsplit(parts._replace(path=parts.path.rstrip("/") + "/scores"))


def _retry_after(answer: transport.Answer) -> float | None:
    value = next((v for k, v in answer.headers.items() if k.lower() == "retry-after"), None)
    try:
        return float(value) if value is not None else None
    except ValueError:
        return None  # an HTTP date: rare enough to fall back on our own backoff


class ScoreService:
    def __init__(self, registrations: Registrations, tokens: AccessTokens) -> None:
        self._registrations, self._tokens = registrations, tokens

    def post(self, issuer: str, client_id: str, lineitem: str, score: Score) -> PostOutcome:
        registration = self._registrations.find(issuer, client_id)
        if registration is None:
            return PostOutcome("refused", f"no registration for {issuer!r} client {client_id!r}")
        answer = None
        for _ in range(2):  # a 401 with a cached token: get a fresh one and try once more
            try:
                token = self._tokens.token(registration, (SCORE_SCOPE,))
            except TokenUnavailable as error:
                return PostOutcome("retry", str(error))
            try:
                answer = transport.call(
                    "POST",
                    scores_url(lineitem),
                    data=json.dumps(score.to_ags()).encode("utf-8"),
                    headers={"Authorization": f"Bearer {token}", "Content-Type": SCORE_MEDIA_TYPE},
                )
            except transport.Unreachable as error:
                return PostOutcome("retry", str(error), platform_down=True)
            if answer.status != 401:
                break
            self._tokens.forget(registration)
        assert answer is not None
        if answer.ok or answer.status == 409:
            return PostOutcome("delivered", answer.reason() if answer.status == 409 else "")
        if answer.status in (401, 429) or answer.status >= 500:
            return PostOutcome("retry", answer.reason(), retry_after_sec=_retry_after(answer))
        return PostOutcome("refused", answer.reason())
