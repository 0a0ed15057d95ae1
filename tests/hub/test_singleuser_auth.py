"""The lean mode's pieces without a hub: the spawner's environment, scopes, signed cookies.

The whole OAuth flow runs against a real hub in test_lean_hub.py.
"""

from __future__ import annotations

import json

import pytest

from app.hub.hub_api import Signer, grants
from app.hub.singleuser_auth import HubSettings, HubSettingsError
from tests.conftest import run_cli

ENV = {
    "JUPYTERHUB_API_TOKEN": "server-token",
    "JUPYTERHUB_API_URL": "http://127.0.0.1:8081/hub/api",
    "JUPYTERHUB_CLIENT_ID": "jupyterhub-user-ada",
    "JUPYTERHUB_OAUTH_CALLBACK_URL": "/user/ada/oauth_callback",
    "JUPYTERHUB_SERVICE_PREFIX": "/user/ada/",
    "JUPYTERHUB_SERVICE_URL": "http://127.0.0.1:47001/user/ada/",
    "JUPYTERHUB_USER": "ada",
    "JUPYTERHUB_OAUTH_ACCESS_SCOPES": json.dumps(
        ["access:servers!server=ada/", "access:servers!user=ada"]
    ),
    "JUPYTERHUB_BASE_URL": "/",
    "JUPYTERHUB_ACTIVITY_URL": "http://127.0.0.1:8081/hub/api/users/ada/activity",
}


def test_the_spawners_environment_says_where_and_for_whom():
    settings = HubSettings.from_env(ENV)
    assert (settings.host, settings.port, settings.prefix) == ("127.0.0.1", 47001, "/user/ada/")
    assert settings.authorize_url == "/hub/api/oauth2/authorize"
    assert settings.activity_interval == 300  # jupyterhub-singleuser's default
    # A hub under a base URL, on its own host, with its own activity interval.
    other = HubSettings.from_env(
        {
            **ENV,
            "JUPYTERHUB_BASE_URL": "/jhub/",
            "JUPYTERHUB_HOST": "https://hub.example.edu",
            "JUPYTERHUB_ACTIVITY_INTERVAL": "60",
            "JUPYTERHUB_COOKIE_OPTIONS": '{"secure": true}',
        }
    )
    assert other.authorize_url == "https://hub.example.edu/jhub/hub/api/oauth2/authorize"
    assert other.activity_interval == 60 and other.secure_cookies


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        ({"JUPYTERHUB_API_TOKEN": ""}, "missing JUPYTERHUB_API_TOKEN"),
        ({"JUPYTERHUB_SERVICE_URL": "https://0.0.0.0:8888/user/ada/"}, "internal TLS"),
        ({"JUPYTERHUB_SERVICE_URL": "http://0.0.0.0/user/ada/"}, "http://HOST:PORT"),
        ({"JUPYTERHUB_SERVICE_PREFIX": "/user/ada"}, "start and end with /"),
        ({"JUPYTERHUB_OAUTH_ACCESS_SCOPES": "[oops"}, "is not JSON"),
        ({"JUPYTERHUB_OAUTH_ACCESS_SCOPES": "[]"}, "names no scope"),
        ({"JUPYTERHUB_ACTIVITY_INTERVAL": "often"}, "must be a number"),
    ],
)
def test_a_wrong_environment_gets_a_clear_reason(change, reason):
    with pytest.raises(HubSettingsError, match=reason.replace("(", r"\(")):
        HubSettings.from_env({**ENV, **change})


def test_serve_jupyterhub_outside_a_hub_is_one_clear_line():
    done = run_cli("serve", "--jupyterhub", env={"PATH": "/usr/bin:/bin"}, timeout=60)
    assert done.returncode == 2, done
    assert "start it from a hub's spawner (missing JUPYTERHUB_API_TOKEN" in done.stderr
    assert "Traceback" not in done.stderr


REQUIRED = frozenset({"access:servers!server=ada/", "access:servers!user=ada"})


@pytest.mark.parametrize(
    ("held", "granted"),
    [
        ({"access:servers!server=ada/"}, True),  # the learner's own OAuth token
        ({"access:servers!user=ada"}, True),
        ({"access:servers"}, True),  # an admin's unfiltered scope
        ({"access:servers!server=bob/", "access:servers!user=bob"}, False),
        ({"access:servers!user=adam"}, False),  # a prefix of a name is not the name
        ({"read:users!user=ada", "users:activity!user=ada"}, False),
        ({"access:servers!group=teachers"}, False),  # groups are the hub's to resolve
        (set(), False),
    ],
)
def test_scopes_grant_access_as_jupyterhub_checks_them(held, granted):
    assert grants(held, REQUIRED) is granted


def test_a_signed_value_comes_back_only_unchanged_fresh_and_under_its_own_name():
    signer = Signer(b"k" * 32)
    signed = signer.sign("jupyterhub-user-ada", "the-token")
    assert signer.unsign("jupyterhub-user-ada", signed, 60) == "the-token"
    assert signer.unsign("jupyterhub-user-bob", signed, 60) is None  # another cookie's name
    assert Signer(b"x" * 32).unsign("jupyterhub-user-ada", signed, 60) is None  # other server
    data, stamp, mac = signed.split("|")
    forged = f"{data[:-2]}AA|{stamp}|{mac}"
    assert signer.unsign("jupyterhub-user-ada", forged, 60) is None
    old = signer.sign("jupyterhub-user-ada", "the-token", now=1_000_000.0)
    assert signer.unsign("jupyterhub-user-ada", old, 60) is None  # too old
    for junk in (None, "", "a|b", "a|b|c|d", "||"):
        assert signer.unsign("jupyterhub-user-ada", junk, 60) is None
