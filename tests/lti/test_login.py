"""OIDC third-party login initiation: the redirect to the LMS's auth endpoint."""

from __future__ import annotations

import urllib.parse

import pytest

from app.lti.login import login_redirect
from app.lti.nonces import NonceStore
from app.lti.registration import Registrations
from app.lti.rejection import LaunchRejected
from app.lti.routes import ToolUrls
from tests.lti.platform import CLIENT_ID, DEPLOYMENT_ID, TestPlatform

URLS = ToolUrls.from_base("https://tool.example.edu/classroom/")


def _params(platform: TestPlatform, **changes: str) -> dict[str, str]:
    values = {
        "iss": platform.issuer,
        "login_hint": "user-hint-9",
        "target_link_uri": URLS.launch,
        "lti_message_hint": "msg-hint-3",
        "client_id": CLIENT_ID,
        "lti_deployment_id": DEPLOYMENT_ID,
    }
    return {k: v for k, v in {**values, **changes}.items() if v}


def test_the_login_request_becomes_the_redirect_the_spec_asks_for(platform: TestPlatform) -> None:
    redirect = login_redirect(
        _params(platform), Registrations([platform.registration()]), NonceStore(), URLS
    )
    parts = urllib.parse.urlsplit(redirect.url)
    assert f"{parts.scheme}://{parts.netloc}{parts.path}" == f"{platform.url}/auth"
    query = urllib.parse.parse_qs(parts.query)
    assert {k: v[0] for k, v in query.items()} == {
        "lms": "moodle",  # the auth URL's own query stays
        "scope": "openid",
        "response_type": "id_token",
        "response_mode": "form_post",
        "prompt": "none",
        "client_id": CLIENT_ID,
        "redirect_uri": "https://tool.example.edu/classroom/lti/launch",
        "login_hint": "user-hint-9",
        "lti_message_hint": "msg-hint-3",
        "state": redirect.state,
        "nonce": redirect.nonce,
    }
    assert len(redirect.state) >= 20 and len(redirect.nonce) >= 20


def test_each_login_gets_its_own_state_and_nonce(platform: TestPlatform) -> None:
    registrations, nonces = Registrations([platform.registration()]), NonceStore()
    first = login_redirect(_params(platform), registrations, nonces, URLS)
    second = login_redirect(_params(platform), registrations, nonces, URLS)
    assert {first.state, first.nonce}.isdisjoint({second.state, second.nonce})


def test_a_deep_linking_login_comes_back_to_the_deep_linking_url(platform: TestPlatform) -> None:
    params = _params(platform, target_link_uri=URLS.deep_link, client_id="")
    redirect = login_redirect(params, Registrations([platform.registration()]), NonceStore(), URLS)
    query = urllib.parse.parse_qs(urllib.parse.urlsplit(redirect.url).query)
    assert query["redirect_uri"] == [URLS.deep_link]
    assert query["client_id"] == [CLIENT_ID]  # the only registration of that issuer


@pytest.mark.parametrize(
    ("changes", "sentence"),
    [
        ({"iss": "https://lms.elsewhere.edu"}, "is not a platform registered with this tool"),
        ({"client_id": "someone-else"}, "client id 'someone-else' is not registered"),
        ({"login_hint": ""}, "has no login_hint"),
        ({"target_link_uri": "https://evil.example.com/x"}, "is not an address of this tool"),
        ({"target_link_uri": "https://tool.example.edu/classroomX"}, "is not an address of"),
        ({"lti_deployment_id": "dep-unknown"}, "deployment 'dep-unknown'"),
    ],
)
def test_a_bad_login_request_is_refused_with_its_reason(
    platform: TestPlatform, changes: dict[str, str], sentence: str
) -> None:
    nonces = NonceStore()
    with pytest.raises(LaunchRejected, match=sentence):
        login_redirect(
            _params(platform, **changes), Registrations([platform.registration()]), nonces, URLS
        )


def test_a_base_url_an_lms_would_refuse_is_refused_here() -> None:
    with pytest.raises(ValueError, match="plain http"):
        ToolUrls.from_base("http://tool.example.edu")
    with pytest.raises(ValueError, match="https://host/path"):
        ToolUrls.from_base("tool.example.edu/classroom")
    assert ToolUrls.from_base("http://127.0.0.1:8080/").jwks == "http://127.0.0.1:8080/lti/jwks"
