"""The teacher service's own hub login (app/hub/service_auth.py), step by step over real HTTP.

A browser's OAuth round trip through a stand-in hub (``TestHub``: its
``/hub/api/user`` and ``/hub/api/oauth2/token`` answer as JupyterHub's do),
and what each wrong turn gets: a forged state, the hub's refusal, a learner's
login, a changed cookie, a hub that does not answer.
"""

from __future__ import annotations

import urllib.parse
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.lti.platform import TestPlatform
from tests.lti.service import PREFIX, Answer, ServiceUnderTest, request
from tests.lti.test_service import start


@pytest.fixture
def service(platform: TestPlatform, tmp_path: Path) -> Iterator[ServiceUnderTest]:
    running = start(tmp_path / "lti", platform)
    yield running
    running.close()


def _get(service: ServiceUnderTest, path: str, cookies: dict[str, str] | None = None) -> Answer:
    jar = "; ".join(f"{k}={v}" for k, v in (cookies or {}).items())
    return request("GET", service.url + path, headers={"Cookie": jar} if jar else {})


def _login_redirect(service: ServiceUnderTest, page: str) -> tuple[str, dict[str, str]]:
    """Open a teacher's page without a login: the hub's authorize URL's state, and our cookies."""
    answer = _get(service, PREFIX + page)
    assert answer.status == 302, answer
    where = urllib.parse.urlsplit(answer.location)
    assert where.path == "/hub/api/oauth2/authorize", answer.location
    query = dict(urllib.parse.parse_qsl(where.query))
    assert query["client_id"] == "service-classroom-teacher"
    assert query["redirect_uri"] == PREFIX + "oauth_callback"
    assert query["response_type"] == "code"
    assert answer.cookies, "no state cookie"
    return query["state"], answer.cookies


def test_a_teacher_logs_in_through_the_hub_and_comes_back_to_the_page_they_asked_for(
    service: ServiceUnderTest,
) -> None:
    state, cookies = _login_redirect(service, "progress.json")
    code = service.hub.code_for(service.hub.teacher_token("mrs-teacher"))
    back = _get(service, f"{PREFIX}oauth_callback?code={code}&state={state}", cookies)
    assert back.status == 302 and back.location == PREFIX + "progress.json", back
    login = {"service-classroom-teacher": back.cookies["service-classroom-teacher"]}
    assert "mrs-teacher" in _get(service, PREFIX, login).body
    assert _get(service, PREFIX + "progress.json", login).status == 200
    # The cookie holds a signed token: changed by one character, it logs nobody in.
    value = login["service-classroom-teacher"]
    forged = {"service-classroom-teacher": value[:-1] + ("0" if value[-1] != "0" else "1")}
    assert _get(service, PREFIX + "progress.json", forged).status == 302  # to the hub again


def test_each_wrong_turn_of_the_login_gets_a_clear_refusal(service: ServiceUnderTest) -> None:
    state, cookies = _login_redirect(service, "")
    teacher_code = service.hub.code_for(service.hub.teacher_token("mrs-teacher"))
    # A state this browser did not start with (a link someone else made).
    forged = _get(service, f"{PREFIX}oauth_callback?code={teacher_code}&state=forged", cookies)
    assert forged.status == 400 and "OAuth state" in forged.body, forged
    # The same callback without the browser's state cookie.
    bare = _get(service, f"{PREFIX}oauth_callback?code={teacher_code}&state={state}")
    assert bare.status == 400, bare
    # The hub refused to log the user in.
    denied = _get(service, f"{PREFIX}oauth_callback?error=access_denied", cookies)
    assert denied.status == 403 and "access_denied" in denied.body, denied
    # A code the hub does not know (made up, or used once already).
    unknown = _get(service, f"{PREFIX}oauth_callback?code=made-up&state={state}", cookies)
    assert unknown.status == 403 and "refused" in unknown.body, unknown
    # A learner logs in fine at the hub, but the hub does not grant them this service.
    learner_code = service.hub.code_for(service.hub.token_for("ada"))
    learner = _get(service, f"{PREFIX}oauth_callback?code={learner_code}&state={state}", cookies)
    assert learner.status == 403 and "ada is not allowed" in learner.body, learner
    assert "service-classroom-teacher" not in learner.cookies


def test_a_hub_that_does_not_answer_is_named_not_a_crash(service: ServiceUnderTest) -> None:
    token = service.hub.teacher_token("mrs-teacher")
    service.hub.close()  # the hub is gone: nothing answers at its API's address
    answer = request("GET", service.url + PREFIX + "progress.json",
                     headers={"Authorization": f"token {token}"})  # fmt: skip
    assert answer.status == 502 and "could not ask the hub" in answer.body, answer
