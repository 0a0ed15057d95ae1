"""The tool's LTI addresses under one base URL: the single place that names them.

A teacher pastes these into the LMS once, and the login step checks a
``target_link_uri`` against them, so the two must never drift apart.
"""

from __future__ import annotations

import urllib.parse
from dataclasses import dataclass

from app.hosts import is_loopback

LOGIN_PATH = "/lti/login"
LAUNCH_PATH = "/lti/launch"
JWKS_PATH = "/lti/jwks"
DEEP_LINK_PATH = "/lti/deep-link"
REGISTER_PATH = "/lti/register"  # LTI Dynamic Registration: the LMS opens it once


@dataclass(frozen=True)
class ToolUrls:
    """Where the LMS finds each LTI endpoint of this deployment."""

    base: str  # no trailing slash, e.g. https://hub.example.edu/services/classroom

    @classmethod
    def from_base(cls, base_url: str) -> ToolUrls:
        """Refuses what no LMS would accept: a relative URL, or plain http to another host."""
        parts = urllib.parse.urlsplit(base_url.strip())
        if parts.scheme not in ("https", "http") or not parts.hostname:
            raise ValueError(f"the base URL must look like https://host/path, got {base_url!r}")
        if parts.query or parts.fragment:
            raise ValueError(f"the base URL must have no query or fragment, got {base_url!r}")
        if parts.scheme == "http" and not is_loopback(parts.hostname):
            raise ValueError(
                f"LMSes only talk to LTI tools over https; {base_url!r} is plain http "
                "(http is allowed for localhost tests only)"
            )
        return cls(urllib.parse.urlunsplit(parts._replace(path=parts.path.rstrip("/"))))

    @property
    def login(self) -> str:
        return self.base + LOGIN_PATH

    @property
    def launch(self) -> str:
        return self.base + LAUNCH_PATH

    @property
    def jwks(self) -> str:
        return self.base + JWKS_PATH

    @property
    def deep_link(self) -> str:
        return self.base + DEEP_LINK_PATH

    @property
    def register(self) -> str:
        return self.base + REGISTER_PATH

    @property
    def redirect_uris(self) -> tuple[str, str]:
        """Where the platform may post an id_token: a launch, or a deep-linking request."""
        return (self.launch, self.deep_link)

    def is_ours(self, url: str) -> bool:
        """True for this base URL and anything under it (not for a look-alike prefix)."""
        return url == self.base or url.startswith(self.base + "/")
