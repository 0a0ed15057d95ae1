"""What the tool knows of each LMS it is registered with (one row per LMS client).

A teacher or administrator copies these values from the LMS's tool set-up
page into ``platforms.toml`` in the service's LTI folder. One issuer may hold
several registrations (Canvas uses one issuer for every school), so a
registration is found by issuer and client_id together.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib


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

    def add(self, registration: PlatformRegistration) -> None:
        """One more platform, live (dynamic registration): the next login already finds it."""
        self._all = (*self._all, registration)

    def for_issuer(self, issuer: str) -> list[PlatformRegistration]:
        return [r for r in self._all if r.issuer == issuer]

    def find(self, issuer: str, client_id: str) -> PlatformRegistration | None:
        return next((r for r in self.for_issuer(issuer) if r.client_id == client_id), None)


_FIELDS = ("issuer", "client_id", "jwks_url", "auth_login_url", "auth_token_url")


def load_registrations(path: Path) -> Registrations:
    """The platforms in a TOML file of ``[[platform]]`` tables; none when the file is absent.

    An administrator writes it by hand from the LMS's tool page, so a mistake names
    the file, the table and the field, and nothing half-read is used.
    """
    if not path.exists():
        return Registrations([])
    try:
        document = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as error:
        raise ValueError(f"{path}: not a readable TOML file ({error})") from None
    tables = document.get("platform", [])
    if not isinstance(tables, list):
        raise ValueError(f"{path}: write each LMS as a [[platform]] table")
    found: list[PlatformRegistration] = []
    for number, table in enumerate(tables, start=1):
        where = f"{path}: platform {number}"
        if not isinstance(table, dict):
            raise ValueError(f"{where} is not a table")
        unknown = sorted(set(table) - {*_FIELDS, "deployment_ids", "token_audience"})
        if unknown:
            raise ValueError(f"{where}: unknown field(s) {', '.join(unknown)}")
        values: dict[str, str] = {}
        for name in _FIELDS:
            value = table.get(name)
            if not isinstance(value, str) or not value.strip():
                raise ValueError(f"{where}: {name} must be a non-empty string")
            values[name] = value.strip()
        deployments = table.get("deployment_ids")
        if (
            not isinstance(deployments, list)
            or not deployments
            or not all(isinstance(d, str) and d for d in deployments)
        ):
            raise ValueError(f"{where}: deployment_ids must be a list of the LMS's deployment ids")
        audience = table.get("token_audience")
        if audience is not None and not isinstance(audience, str):
            raise ValueError(f"{where}: token_audience must be a string")
        found.append(
            PlatformRegistration(
                deployment_ids=frozenset(deployments), token_audience=audience, **values
            )
        )
    pairs = [(r.issuer, r.client_id) for r in found]
    if len(set(pairs)) != len(pairs):
        raise ValueError(f"{path}: one issuer and client_id are registered twice")
    return Registrations(found)
