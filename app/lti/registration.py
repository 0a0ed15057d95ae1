"""What the tool knows of each LMS it is registered with (one row per LMS client).

A teacher or administrator copies these values from the LMS's tool set-up
page. One issuer may hold several registrations (Canvas uses one issuer for
every school), so a registration is found by issuer and client_id together.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass


@dataclass(frozen=True)
class PlatformRegistration:
    issuer: str
    client_id: str
    deployment_ids: frozenset[str]
    jwks_url: str  # the platform's public keys
    auth_login_url: str  # where the OIDC login step sends the browser
    auth_token_url: str  # the OAuth 2 token endpoint for grade passback
    # The `aud` of our client assertion; most platforms want the token URL itself,
    # a few (some Brightspace set-ups) name another audience.
    token_audience: str | None = None

    @property
    def assertion_audience(self) -> str:
        return self.token_audience or self.auth_token_url


class Registrations:
    """All registered platforms, looked up the way a login or launch names them."""

    def __init__(self, registrations: Iterable[PlatformRegistration]) -> None:
        self._all = tuple(registrations)

    def __iter__(self) -> Iterator[PlatformRegistration]:
        return iter(self._all)

    def for_issuer(self, issuer: str) -> list[PlatformRegistration]:
        return [r for r in self._all if r.issuer == issuer]

    def find(self, issuer: str, client_id: str) -> PlatformRegistration | None:
        return next((r for r in self.for_issuer(issuer) if r.client_id == client_id), None)
