"""OIDC third-party login initiation: the LMS's first request, answered with a redirect.

The LMS sends the browser here with who it is and who the learner is; we
send the browser on to the LMS's auth endpoint with a fresh state and nonce,
and the LMS then posts the signed id_token to our launch URL.
"""

from __future__ import annotations

import urllib.parse
from collections.abc import Mapping
from dataclasses import dataclass

from app.lti.nonces import NonceStore
from app.lti.registration import PlatformRegistration, Registrations
from app.lti.rejection import LaunchRejected
from app.lti.routes import ToolUrls


@dataclass(frozen=True)
class LoginRedirect:
    url: str  # where to send the browser (HTTP 302)
    state: str  # the launch must bring this back; a web layer may also pin it in a cookie
    nonce: str


def _registration(params: Mapping[str, str], registrations: Registrations) -> PlatformRegistration:
    issuer = params.get("iss", "")
    if not issuer:
        raise LaunchRejected("the login request names no issuer (iss)")
    candidates = registrations.for_issuer(issuer)
    if not candidates:
        raise LaunchRejected(f"the issuer {issuer!r} is not a platform registered with this tool")
    client_id = params.get("client_id")
    if client_id:
        found = registrations.find(issuer, client_id)
        if found is None:
            raise LaunchRejected(f"client id {client_id!r} is not registered for {issuer!r}")
        return found
    if len(candidates) > 1:
        raise LaunchRejected(
            f"{issuer!r} has several registrations here and the login request names no "
            "client_id to choose one"
        )
    return candidates[0]


def login_redirect(
    params: Mapping[str, str], registrations: Registrations, nonces: NonceStore, urls: ToolUrls
) -> LoginRedirect:
    """The redirect for the LMS's login request ``params`` (its query or form fields)."""
    registration = _registration(params, registrations)
    login_hint = params.get("login_hint", "")
    if not login_hint:
        raise LaunchRejected("the login request has no login_hint")
    target = params.get("target_link_uri", "")
    if not urls.is_ours(target):
        raise LaunchRejected(
            f"the login request's target_link_uri {target!r} is not an address of this tool "
            f"({urls.base})"
        )
    deployment_id = params.get("lti_deployment_id")
    if deployment_id and deployment_id not in registration.deployment_ids:
        raise LaunchRejected(
            f"deployment {deployment_id!r} of {registration.issuer} is not registered"
        )
    pair = nonces.issue()
    query = {
        "scope": "openid",
        "response_type": "id_token",
        "response_mode": "form_post",
        "prompt": "none",
        "client_id": registration.client_id,
        # A deep-linking request comes back to the deep-linking URL, everything else to launch.
        "redirect_uri": target if target in urls.redirect_uris else urls.launch,
        "login_hint": login_hint,
        "state": pair.state,
        "nonce": pair.nonce,
    }
    if params.get("lti_message_hint"):
        query["lti_message_hint"] = params["lti_message_hint"]
    parts = urllib.parse.urlsplit(registration.auth_login_url)
    joined = "&".join(filter(None, [parts.query, urllib.parse.urlencode(query)]))
    return LoginRedirect(
        urllib.parse.urlunsplit(parts._replace(query=joined)), pair.state, pair.nonce
    )
