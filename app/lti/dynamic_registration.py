"""LTI Dynamic Registration 1.0: the LMS registers the tool itself, no values to paste.

An administrator pastes one URL into the LMS (``ToolUrls.register``); the LMS
opens it in a window with ``openid_configuration`` (where its configuration
is) and usually ``registration_token``. We read the configuration, post our
client registration to its ``registration_endpoint``, store the answer in
``platforms.toml`` as a hand-written registration is stored, and answer a
page that tells the LMS we are done (``org.imsglobal.lti.close``).

Nothing is stored unless every step succeeded; a refusal says which step
and why. Spec: https://www.imsglobal.org/spec/lti-dr/v1p0

The URL carries a key of this deployment (``registration-key`` in the LTI
folder, made on first use): without it, anyone could register an "LMS" of
their own and have the hub make accounts for its launches. The LMS keeps
the URL's query when it adds its own parameters (Moodle and Canvas do).
"""

from __future__ import annotations

import hmac
import html
import json
import os
import secrets
import threading
import urllib.parse
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

from app.hosts import is_loopback
from app.jsonish import JSONObject
from app.lti import transport
from app.lti.claims import SCORE_SCOPE
from app.lti.lms_setup import LINEITEM_SCOPE, TOOL_TITLE
from app.lti.registration import PlatformRegistration, load_registrations
from app.lti.routes import ToolUrls
from app.lti.tool import PLATFORMS_FILE

PLATFORM_CONFIGURATION = "https://purl.imsglobal.org/spec/lti-platform-configuration"
TOOL_CONFIGURATION = "https://purl.imsglobal.org/spec/lti-tool-configuration"
# The id_token claims the tool reads (the LMS may leave out what its privacy settings keep).
CLAIMS = ("iss", "sub", "name", "given_name", "family_name", "email")
_store_lock = threading.Lock()  # two registrations at once must not lose one


KEY_FILE = "registration-key"


def registration_key(folder: Path) -> str:
    """This deployment's registration key, made (readable by its owner only) on first use."""
    path = folder / KEY_FILE
    if not path.exists():
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w", encoding="ascii") as out:
            out.write(secrets.token_urlsafe(24) + "\n")
    return path.read_text(encoding="ascii").strip()


def registration_url(urls: ToolUrls, folder: Path) -> str:
    """What the administrator pastes into the LMS's "register a tool by URL" field."""
    return f"{urls.register}?{urllib.parse.urlencode({'key': registration_key(folder)})}"


class RegistrationRefused(Exception):
    """Dynamic registration stopped; the message says at which step and why."""


@dataclass(frozen=True)
class PlatformConfiguration:
    """What the LMS's openid-configuration says that registration needs."""

    issuer: str
    authorization_endpoint: str
    token_endpoint: str
    jwks_uri: str
    registration_endpoint: str
    token_audience: str | None  # authorization_server, when it differs from the token URL
    product: str  # the LMS's product_family_code, for the log


def _check_url(url: str, what: str) -> urllib.parse.SplitResult:
    parts = urllib.parse.urlsplit(url)
    if parts.scheme not in ("https", "http") or not parts.hostname:
        raise RegistrationRefused(f"{what} {url!r} is not an https URL")
    if parts.scheme == "http" and not is_loopback(parts.hostname):
        raise RegistrationRefused(
            f"{what} {url!r} is plain http: an LMS registers tools over https only"
        )
    return parts


def _origin(parts: urllib.parse.SplitResult) -> tuple[str, str, int | None]:
    default = 443 if parts.scheme == "https" else 80
    return (parts.scheme, (parts.hostname or "").lower(), parts.port or default)


def _json(answer: transport.Answer, what: str) -> dict[str, object]:
    try:
        document = answer.json()
    except ValueError:
        raise RegistrationRefused(f"{what} is not JSON: {answer.reason(120)}") from None
    if not isinstance(document, dict):
        raise RegistrationRefused(f"{what} is not a JSON object: {answer.reason(120)}")
    return document


def _text(document: Mapping[str, object], name: str, what: str) -> str:
    value = document.get(name)
    if not isinstance(value, str) or not value.strip():
        raise RegistrationRefused(f"{what} has no {name}")
    return value.strip()


def read_configuration(url: str) -> PlatformConfiguration:
    """The LMS's configuration at ``url``, checked as the specification asks."""
    where = _check_url(url, "the LMS's configuration URL (openid_configuration)")
    try:
        answer = transport.call("GET", url, headers={"Accept": "application/json"})
    except transport.Unreachable as error:
        raise RegistrationRefused(f"the LMS's configuration could not be read: {error}") from None
    if not answer.ok:
        raise RegistrationRefused(f"the LMS's configuration answered {answer.reason()}")
    what = "the LMS's configuration"
    document = _json(answer, what)
    issuer = _text(document, "issuer", what)
    # The issuer must be the configuration's own site: a configuration that names
    # another LMS as its issuer could have launches signed in that LMS's name.
    if _origin(_check_url(issuer, "the LMS's issuer")) != _origin(where):
        raise RegistrationRefused(
            f"the LMS's configuration at {url!r} names the issuer {issuer!r}, which is not "
            "the same site: the issuer must match the configuration URL"
        )
    endpoints = {
        name: _text(document, name, what)
        for name in ("authorization_endpoint", "token_endpoint", "jwks_uri")
    }
    registration = _text(document, "registration_endpoint", what)
    for name, value in [*endpoints.items(), ("registration_endpoint", registration)]:
        _check_url(value, f"the LMS's {name}")
    platform = document.get(PLATFORM_CONFIGURATION)
    product = platform.get("product_family_code") if isinstance(platform, dict) else None
    audience = document.get("authorization_server")
    return PlatformConfiguration(
        issuer=issuer,
        registration_endpoint=registration,
        token_audience=audience if isinstance(audience, str) and audience else None,
        product=product if isinstance(product, str) else "an LMS",
        **endpoints,
    )


def client_registration(urls: ToolUrls) -> JSONObject:
    """Our OpenID client registration with the LTI tool configuration, as the LMS reads it."""
    domain = urllib.parse.urlsplit(urls.base).netloc
    return {
        "application_type": "web",
        "response_types": ["id_token"],
        "grant_types": ["implicit", "client_credentials"],
        "initiate_login_uri": urls.login,
        "redirect_uris": list(urls.redirect_uris),
        "client_name": TOOL_TITLE,
        "jwks_uri": urls.jwks,
        "token_endpoint_auth_method": "private_key_jwt",
        "scope": " ".join([SCORE_SCOPE, LINEITEM_SCOPE]),
        TOOL_CONFIGURATION: {
            "domain": domain,
            "description": "ROS 2 lessons and exercises, graded on a live ROS 2 graph.",
            "target_link_uri": urls.launch,
            "claims": list(CLAIMS),
            "messages": [
                {"type": "LtiResourceLinkRequest", "target_link_uri": urls.launch},
                {
                    "type": "LtiDeepLinkingRequest",
                    "target_link_uri": urls.deep_link,
                    "label": f"Add a {TOOL_TITLE} activity",
                    "placements": ["ContentArea"],
                    "supported_types": ["ltiResourceLink"],
                },
            ],
        },
    }


def _post_registration(
    configuration: PlatformConfiguration, urls: ToolUrls, token: str
) -> dict[str, object]:
    headers = {"Content-Type": "application/json", "Accept": "application/json"}
    if token:
        headers["Authorization"] = f"Bearer {token}"
    body = json.dumps(client_registration(urls)).encode("utf-8")
    try:
        answer = transport.call(
            "POST", configuration.registration_endpoint, data=body, headers=headers
        )
    except transport.Unreachable as error:
        raise RegistrationRefused(f"the LMS's registration endpoint: {error}") from None
    if not answer.ok:
        raise RegistrationRefused(f"the LMS refused the registration: {answer.reason()}")
    return _json(answer, "the LMS's answer to the registration")


def registration_from_answer(
    configuration: PlatformConfiguration, answer: Mapping[str, object]
) -> PlatformRegistration:
    what = "the LMS's answer to the registration"
    client_id = _text(answer, "client_id", what)
    tool = answer.get(TOOL_CONFIGURATION)
    deployment = tool.get("deployment_id") if isinstance(tool, dict) else None
    if not isinstance(deployment, str) or not deployment:
        raise RegistrationRefused(
            f"{what} gives client id {client_id!r} but no deployment_id: deploy the tool in "
            "the LMS, then add its deployment id to platforms.toml by hand"
        )
    return PlatformRegistration(
        issuer=configuration.issuer,
        client_id=client_id,
        deployment_ids=frozenset({deployment}),
        jwks_url=configuration.jwks_uri,
        auth_login_url=configuration.authorization_endpoint,
        auth_token_url=configuration.token_endpoint,
        token_audience=configuration.token_audience,
    )


def _toml_text(value: str) -> str:
    return json.dumps(value)  # a JSON string is a valid TOML basic string


def platform_table(registration: PlatformRegistration, source: str) -> str:
    """The ``[[platform]]`` table an administrator would have written for ``registration``."""
    stamp = datetime.now(timezone.utc).isoformat(timespec="seconds")
    lines = [
        f"# Added by dynamic registration from {source} on {stamp}",
        "[[platform]]",
        f"issuer = {_toml_text(registration.issuer)}",
        f"client_id = {_toml_text(registration.client_id)}",
        "deployment_ids = ["
        + ", ".join(_toml_text(d) for d in sorted(registration.deployment_ids))
        + "]",
        f"jwks_url = {_toml_text(registration.jwks_url)}",
        f"auth_login_url = {_toml_text(registration.auth_login_url)}",
        f"auth_token_url = {_toml_text(registration.auth_token_url)}",
    ]
    if registration.token_audience:
        lines.append(f"token_audience = {_toml_text(registration.token_audience)}")
    return "\n".join(lines) + "\n"


def store(registration: PlatformRegistration, path: Path, source: str) -> None:
    """Add ``registration`` to ``platforms.toml``; the file is replaced whole or not at all."""
    known = load_registrations(path)
    if known.find(registration.issuer, registration.client_id) is not None:
        raise RegistrationRefused(
            f"{registration.issuer} client {registration.client_id!r} is already registered "
            f"in {path}"
        )
    before = path.read_text(encoding="utf-8") if path.exists() else ""
    text = before + ("\n" if before and not before.endswith("\n\n") else "")
    text += platform_table(registration, source)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(path.name + ".new")
    partial.write_text(text, encoding="utf-8")
    try:
        load_registrations(partial)  # what we wrote reads back, or nothing changes
    except ValueError as error:
        partial.unlink()
        raise RegistrationRefused(f"the registration could not be written: {error}") from None
    os.replace(partial, path)


def register(params: Mapping[str, str], urls: ToolUrls, folder: Path) -> PlatformRegistration:
    """The whole registration for the LMS's request ``params``; ``RegistrationRefused``.

    ``folder`` is the tool's LTI folder: its registration key and its platforms.toml.
    """
    if not hmac.compare_digest(params.get("key", ""), registration_key(folder)):
        raise RegistrationRefused(
            "the registration URL lacks this deployment's key: paste the whole URL that "
            "`ros2-classroom lti config` prints into the LMS"
        )
    url = params.get("openid_configuration", "").strip()
    if not url:
        raise RegistrationRefused(
            "the request has no openid_configuration: start the registration from the LMS"
        )
    configuration = read_configuration(url)
    answer = _post_registration(configuration, urls, params.get("registration_token", ""))
    registration = registration_from_answer(configuration, answer)
    with _store_lock:
        store(registration, folder / PLATFORMS_FILE, url)
    return registration


def close_page(registration: PlatformRegistration) -> str:
    """The last page: says what was registered, and tells the LMS to close the window."""
    what = html.escape(f"{registration.issuer} (client id {registration.client_id})")
    message = json.dumps({"subject": "org.imsglobal.lti.close"})
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        f"<title>Registered: {html.escape(TOOL_TITLE)}</title></head>\n<body>\n"
        f"<h1>{html.escape(TOOL_TITLE)} is registered</h1>\n"
        f'<p id="registered">Registered with {what}. You can close this window.</p>\n'
        f"<script>(window.opener || window.parent).postMessage({message}, '*');</script>\n"
        "</body></html>\n"
    )
