"""LTI 1.3 end to end against a platform we did not write: ``lti1p3platform`` from PyPI.

The LMS side (tests/lti/pypi_platform.py) makes every message with that
library: the OIDC login initiation, the signed id_tokens (launch and
deep-linking request, with their AGS and deep-linking claims), the JWKS, the
token endpoint that checks our client assertion against our keyset URL, the
check of our deep-linking answer, and the AGS score endpoint that checks our
bearer token. The tool side is the teacher service as tests/lti/test_service.py
serves it. The whole teacher-and-learner flow runs in headless Chromium; the
refusals go over plain HTTP, one request at a time, to read each page.
"""

from __future__ import annotations

import html
import json
import re
import time
import urllib.parse
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from lti1p3platform.registration import Registration

from app.lti import claims
from app.lti.dynamic_registration import registration_url
from app.lti.learners import hub_user_name
from app.lti.registration import load_registrations
from app.lti.tool import PLATFORMS_FILE
from app.teacher.record import GradedAttempt
from tests.lti.pypi_platform import DEPLOYMENT_ID, LaunchQuirk, PypiPlatform, key_pair
from tests.lti.service import PREFIX, Answer, ServiceUnderTest, request, wait_for
from tests.lti.test_service import EXERCISE, LESSON, exercise_record, hub_login, refusal


@pytest.fixture
def lms() -> Iterator[PypiPlatform]:
    platform = PypiPlatform()
    yield platform
    platform.close()


@pytest.fixture
def service(lms: PypiPlatform, tmp_path: Path) -> Iterator[ServiceUnderTest]:
    folder = tmp_path / "lti"
    folder.mkdir()
    (folder / PLATFORMS_FILE).write_text(lms.platforms_toml())
    running = ServiceUnderTest(folder)
    lms.register_tool(running.urls)
    yield running
    running.close()


# A browser's part, over plain HTTP ---------------------------------------------------------


def follow(url: str, limit: int = 5) -> tuple[str, Answer]:
    """GET ``url`` and the redirects after it, as a browser does; the last URL and answer."""
    for _ in range(limit):
        answer = request("GET", url)
        if answer.status not in (302, 303):
            return url, answer
        url = urllib.parse.urljoin(url, answer.location)
    raise AssertionError(f"more than {limit} redirects, the last to {url}")


def signed_form(lms: PypiPlatform, user: str, link: str | None) -> tuple[str, dict[str, str]]:
    """The platform's auto-submitting launch form after the login round: action and fields."""
    where, page = follow(lms.start(user, link))
    assert where.startswith(f"{lms.url}/auth?"), page.body
    assert page.status == 200, page.body
    action = html.unescape(re.findall(r'action="([^"]+)"', page.body)[0])
    fields = dict(re.findall(r'name="(id_token|state)" value="([^"]+)"', page.body))
    return action, fields


def http_launch(lms: PypiPlatform, user: str, link: str | None) -> Answer:
    action, fields = signed_form(lms, user, link)
    return request("POST", action, form=fields)


# Launch ----------------------------------------------------------------------------------------


def test_a_learner_launched_by_the_pypi_platform_is_mapped_to_their_own_server(
    service: ServiceUnderTest, lms: PypiPlatform
) -> None:
    lms.add_link("link-1", {"exercise": EXERCISE}, item="7")
    answer = http_launch(lms, "learner-1", "link-1")
    user = hub_login(service, answer)
    assert user is not None
    name = hub_user_name(lms.issuer, "learner-1")
    assert (user["name"], user["lti_next"], user["lti_teacher"]) == (
        name,
        f"/user/{name}/?exercise={EXERCISE}",
        False,
    )
    # Another learner of the course is another learner here; the teacher goes to the
    # teacher's page (the library's Instructor role).
    other = hub_login(service, http_launch(lms, "learner-2", "link-1"))
    assert other is not None and other["name"] == hub_user_name(lms.issuer, "learner-2")
    teacher = hub_login(service, http_launch(lms, "teacher-1", "link-1"))
    assert teacher is not None and (teacher["lti_next"], teacher["lti_teacher"]) == (PREFIX, True)


# The whole flow in a browser -------------------------------------------------------------------


@pytest.mark.browser
def test_a_teacher_adds_an_exercise_a_learner_passes_it_and_the_platform_gets_the_grade(
    service: ServiceUnderTest, lms: PypiPlatform, browser: Any
) -> None:
    context = browser.new_context()
    page = context.new_page()
    try:
        # The teacher adds an activity: the platform's deep-linking launch opens our picker.
        page.goto(lms.start("teacher-1"))
        page.get_by_role("heading", name="Add a ROS 2 Classroom activity").wait_for()
        page.locator(f'input[name="pick"][value="exercise:{EXERCISE}"]').check()
        page.locator(f'input[name="points-exercise:{EXERCISE}"]').fill("5")
        page.get_by_role("button", name="Add to the course").click()
        # Our signed answer auto-posts to the platform, which checks it with the library.
        page.locator("#lms").wait_for()
        assert '"added": 1' in page.locator("#lms").inner_text(), lms.deep_link_refusals
        [(link_id, link)] = lms.links.items()
        assert link.custom == {"exercise": EXERCISE, "score_maximum": "5"}
        item = link_id.removeprefix("link-")
        assert lms.lineitems[item]["scoreMaximum"] == 5
        assert lms.lineitems[item]["resourceId"] == f"exercise:{EXERCISE}"

        # A learner opens the new link from the course page.
        page.goto(lms.start("learner-1", link_id))
        # Our launch sends the browser on to the hub's handoff page (no hub runs here).
        page.wait_for_url("**/hub/lti-handoff?ticket=*")
        handoff = page.url
    finally:
        context.close()
    relative = handoff.removeprefix(service.url)
    user = hub_login(service, Answer(303, {"location": relative}, ""))
    assert user is not None and user["name"] == hub_user_name(lms.issuer, "learner-1")

    # They pass the exercise on their dashboard (after a failed grading): the score reaches
    # the platform's AGS endpoint, and the report carries both gradings with their seeds.
    tried = (
        GradedAttempt(time.time() - 30, "pass", 4242, 3, 3, (), "3 of 3 checks passed: passed."),
        GradedAttempt(time.time() - 90, "fail", 1717, 2, 3, ("probe /count: sent 5, got 4",)),
    )
    passed = replace(exercise_record(user["name"], passed=True), exercise_history=tried)
    started = time.monotonic()
    assert service.report(passed).status == 200
    wait_for(lambda: bool(lms.scores[item]), why="the score at the platform")
    latency = time.monotonic() - started
    [score] = lms.scores[item]
    assert score["userId"] == "learner-1"
    assert (score["scoreGiven"], score["scoreMaximum"]) == (5, 5)
    assert (score["activityProgress"], score["gradingProgress"]) == ("Completed", "FullyGraded")
    assert f"Exercise {EXERCISE} passed" in score["comment"]
    assert score["timestamp"].endswith("+00:00")
    assert latency < 5  # the lti_score_latency_p95_s bound, on one score
    assert lms.token_answers == [200] and lms.score_answers == [200]

    # The teacher opens the gradebook and clicks the learner's cell of that exercise.
    teacher = service.hub.teacher_token("mrs-teacher")
    context = browser.new_context(extra_http_headers={"Authorization": f"token {teacher}"})
    page = context.new_page()
    try:
        page.goto(service.url + PREFIX + "gradebook")
        cell = page.locator("#class-grid tbody td a")
        assert cell.inner_text().strip() == "✓ 5 of 5"
        cell.click()
        page.wait_for_url("**/gradebook/attempts?*")
        rows = page.locator("#attempts tbody tr")
        assert rows.count() == 2
        newest, failed = rows.nth(0).inner_text(), rows.nth(1).inner_text()
        assert "✓ passed" in newest and "4242" in newest
        assert f"exercise check {EXERCISE} FILE --seed 4242" in newest
        assert "✗ failed" in failed and "1717" in failed and "probe /count: sent 5, got 4" in failed
        lms_side = page.locator("#lms").inner_text()
        assert "✓ sent" in lms_side and "5 of 5" in lms_side
        assert "no replay button here" in page.locator("#replay + p").inner_text()
        page.get_by_role("link", name="Back to the gradebook").click()
        page.locator("#class-grid").wait_for()
    finally:
        context.close()


# Grades the platform refuses -----------------------------------------------------------------


def test_a_score_for_a_learner_the_platform_no_longer_knows_is_kept_with_its_reason(
    service: ServiceUnderTest, lms: PypiPlatform
) -> None:
    lms.add_link("link-1", {"exercise": EXERCISE, "score_maximum": "5"}, item="7")
    user = hub_login(service, http_launch(lms, "learner-2", "link-1"))
    assert user is not None
    del lms.users["learner-2"]  # unenrolled between the launch and the pass
    assert service.report(exercise_record(user["name"], passed=True)).status == 200
    wait_for(lambda: lms.score_answers == [403], why="the platform's answer")
    wait_for(
        lambda: any(e.status == "failed" for e in service.tool.outbox.entries()),
        why="the outbox to mark the score refused",
    )
    [entry] = service.tool.outbox.entries()
    assert "HTTP 403" in entry.reason and "notapplied" in entry.reason
    assert lms.scores["7"] == []


# Refusals: every id_token below is signed by the library ---------------------------------------


def _other_key_registration(lms: PypiPlatform, *, same_kid: bool) -> Registration:
    """The same platform's registration with another private key (an attacker's)."""
    private, public = key_pair()
    forged = lms.tool_registration(_tool(lms), private, public)
    if same_kid:
        real_kid = lms.registration.get_kid()
        forged.get_kid = lambda: real_kid  # type: ignore[method-assign]
    return forged


def _tool(lms: PypiPlatform) -> Any:
    assert lms.tool is not None
    return lms.tool


def test_what_the_tool_refuses_from_the_pypi_platform_gets_a_page_that_says_why(
    service: ServiceUnderTest, lms: PypiPlatform, tmp_path: Path
) -> None:
    lms.add_link("link-1", {"lesson": LESSON}, item="8")

    def refused_launch(quirk: LaunchQuirk) -> str:
        lms.next_quirk = quirk
        return refusal(http_launch(lms, "learner-1", "link-1"))

    # Signed with a key that is not in the platform's JWKS (the library names it by its
    # thumbprint), then re-signed with another key under the platform's own kid.
    forged = _other_key_registration(lms, same_kid=False)
    assert "has no key with kid" in refused_launch(LaunchQuirk(registration=forged))
    resigned = _other_key_registration(lms, same_kid=True)
    assert "signature does not match the platform's key" in refused_launch(
        LaunchQuirk(registration=resigned)
    )
    # Meant for another tool.
    wrong_aud = {"aud": "another-tool", "azp": "another-tool"}
    assert "is meant for audience 'another-tool'" in refused_launch(
        LaunchQuirk(extra_claims=wrong_aud)
    )
    # Expired an hour ago (the library sets exp = iat + the life it is given).
    assert "the id_token expired at" in refused_launch(LaunchQuirk(expires_in=-3600))
    # A deployment of the platform that was never registered here.
    assert "deployment 'another-deployment'" in refused_launch(
        LaunchQuirk(extra_claims={claims.DEPLOYMENT_ID: "another-deployment"})
    )
    # A replayed launch: the same signed form posted twice.
    action, fields = signed_form(lms, "learner-1", "link-1")
    assert request("POST", action, form=fields).status == 303
    assert "this launch is a replay" in refusal(request("POST", action, form=fields))
    # Nothing was recorded for any refused launch: one learner, from the one good launch.
    assert [e.name for e in service.tool.book.learners()] == [
        hub_user_name(lms.issuer, "learner-1")
    ]

    # A platform built with the same library that was never registered with the tool.
    stranger = PypiPlatform(key_index=1)
    try:
        stranger.register_tool(service.urls)
        stranger.add_link("link-1", {"lesson": LESSON})
        _, page = follow(stranger.start("learner-1", "link-1"))
        assert f"the issuer {stranger.issuer!r} is not a platform registered" in refusal(page)
    finally:
        stranger.close()


# Dynamic registration (LTI Dynamic Registration 1.0) -------------------------------------------
# lti1p3platform has no registration service: the LMS's configuration and registration
# endpoints are a stand-in in tests/lti/pypi_platform.py; the launch after it is the library's.


@pytest.fixture
def unregistered(lms: PypiPlatform, tmp_path: Path) -> Iterator[ServiceUnderTest]:
    """The tool with no LMS registered yet (no platforms.toml)."""
    running = ServiceUnderTest(tmp_path / "lti")
    lms.register_tool(running.urls)
    yield running
    running.close()


def open_registration(service: ServiceUnderTest, **params: str) -> Answer:
    """What the LMS's window opens: our registration URL with its own parameters added."""
    url = registration_url(service.urls, service.folder)
    return request("GET", f"{url}&{urllib.parse.urlencode(params)}")


def test_an_lms_registers_the_tool_by_itself_and_launches_with_what_it_assigned(
    unregistered: ServiceUnderTest, lms: PypiPlatform
) -> None:
    service = unregistered
    answer = open_registration(
        service,
        openid_configuration=lms.openid_configuration,
        registration_token=lms.registration_token,
    )
    assert answer.status == 200, answer.body
    assert '{"subject": "org.imsglobal.lti.close"}' in answer.body
    assert "window.opener || window.parent" in answer.body
    [sent] = lms.registrations_received
    assert sent["application_type"] == "web" and sent["response_types"] == ["id_token"]
    assert sent["grant_types"] == ["implicit", "client_credentials"]
    assert sent["initiate_login_uri"] == service.urls.login
    assert sent["redirect_uris"] == [service.urls.launch, service.urls.deep_link]
    assert sent["jwks_uri"] == service.urls.jwks
    assert sent["token_endpoint_auth_method"] == "private_key_jwt"
    assert claims.SCORE_SCOPE in sent["scope"].split()
    tool = sent["https://purl.imsglobal.org/spec/lti-tool-configuration"]
    assert tool["target_link_uri"] == service.urls.launch
    assert tool["domain"] == urllib.parse.urlsplit(service.url).netloc
    assert {m["type"]: m["target_link_uri"] for m in tool["messages"]} == {
        "LtiResourceLinkRequest": service.urls.launch,
        "LtiDeepLinkingRequest": service.urls.deep_link,
    }
    # Kept where a pasted registration is kept, and read back the same way.
    [stored] = load_registrations(service.folder / PLATFORMS_FILE)
    assert (stored.issuer, stored.client_id) == (lms.issuer, "dynamic-client-1")
    assert stored.deployment_ids == frozenset({DEPLOYMENT_ID})
    assert (stored.jwks_url, stored.auth_login_url, stored.auth_token_url) == (
        f"{lms.url}/jwks",
        f"{lms.url}/auth",
        f"{lms.url}/token",
    )
    # The running tool knows it at once: the library's launch with the new client id works.
    lms.register_tool(service.urls)  # the LMS's record of the tool, with the id it assigned
    lms.add_link("link-1", {"exercise": EXERCISE}, item="7")
    user = hub_login(service, http_launch(lms, "learner-1", "link-1"))
    assert user is not None and user["name"] == hub_user_name(lms.issuer, "learner-1")
    # The same registration twice is refused, and the file keeps one.
    tool_configuration = "https://purl.imsglobal.org/spec/lti-tool-configuration"
    lms.registration_reply = (
        200,
        json.dumps(
            {"client_id": "dynamic-client-1", tool_configuration: {"deployment_id": "d-2"}}
        ).encode(),
    )
    again = open_registration(
        service,
        openid_configuration=lms.openid_configuration,
        registration_token=lms.registration_token,
    )
    assert "is already registered" in refusal(again)
    assert len(list(load_registrations(service.folder / PLATFORMS_FILE))) == 1


def test_a_bad_registration_gets_a_page_that_says_why_and_nothing_is_stored(
    unregistered: ServiceUnderTest, lms: PypiPlatform
) -> None:
    service = unregistered
    good = {
        "openid_configuration": lms.openid_configuration,
        "registration_token": lms.registration_token,
    }
    url = service.urls.register
    no_key = request("GET", f"{url}?{urllib.parse.urlencode(good)}")
    assert "lacks this deployment's key" in refusal(no_key)
    forged = request("GET", f"{url}?{urllib.parse.urlencode({**good, 'key': 'guess'})}")
    assert "lacks this deployment's key" in refusal(forged)
    assert "no openid_configuration" in refusal(open_registration(service))
    plain = open_registration(
        service, openid_configuration="http://lms.example.edu/.well-known/openid-configuration"
    )
    assert "is plain http" in refusal(plain)
    # A configuration that names another site as its issuer.
    lms.configuration_changes = {"issuer": "https://lms.elsewhere.edu"}
    assert "the issuer must match the configuration URL" in refusal(
        open_registration(service, **good)
    )
    lms.configuration_changes = {"registration_endpoint": None}
    assert "has no registration_endpoint" in refusal(open_registration(service, **good))
    lms.configuration_changes = {}
    # The LMS refuses the registration token, or answers garbage, or no deployment.
    wrong_token = {**good, "registration_token": "expired"}
    assert "the LMS refused the registration: HTTP 401" in refusal(
        open_registration(service, **wrong_token)
    )
    lms.registration_reply = (200, b"<html>Moodle is being upgraded</html>")
    assert "is not JSON" in refusal(open_registration(service, **good))
    lms.registration_reply = (200, b'{"client_id": "c-9"}')
    assert "no deployment_id" in refusal(open_registration(service, **good))
    lms.registration_reply = (500, b'{"error": "server_error"}')
    assert "HTTP 500" in refusal(open_registration(service, **good))
    assert not (service.folder / PLATFORMS_FILE).exists()
    assert list(service.tool.registrations) == []
