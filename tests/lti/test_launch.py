"""Launches from the test LMS: a good one is read right, each bad one refused with its reason."""

from __future__ import annotations

import time

import pytest
from cryptography.hazmat.primitives.asymmetric import rsa

from app.lti import claims
from app.lti.launch import LaunchValidator
from app.lti.nonces import NonceStore
from app.lti.platform_keys import PlatformKeys
from app.lti.registration import Registrations
from app.lti.rejection import LaunchRejected
from tests.lti.platform import CLIENT_ID, DEPLOYMENT_ID, TestPlatform

INSTRUCTOR = "http://purl.imsglobal.org/vocab/lis/v2/membership#Instructor"


class Tool:
    """The tool's side of a launch: its nonce store and its validator."""

    def __init__(self, platform: TestPlatform) -> None:
        self.nonces = NonceStore()
        self.validator = LaunchValidator(Registrations([platform.registration()]), self.nonces)


@pytest.fixture
def tool(platform: TestPlatform) -> Tool:
    return Tool(platform)


def test_a_good_launch_yields_who_came_and_for_what(platform: TestPlatform, tool: Tool) -> None:
    login = tool.nonces.issue()
    launch = tool.validator.validate(platform.id_token(login.nonce), login.state)
    assert launch.registration.issuer == platform.issuer
    assert launch.registration.client_id == CLIENT_ID
    assert launch.message_type == "LtiResourceLinkRequest"
    assert launch.deployment_id == DEPLOYMENT_ID
    assert (launch.user_id, launch.name, launch.email) == (
        "learner-42",
        "Ada Lovelace",
        "ada@example.edu",
    )
    assert not launch.is_instructor
    assert launch.resource_link_id == "link-3"
    assert launch.context_id == "course-101"
    assert (launch.lesson, launch.exercise) == ("05_topics", None)
    assert launch.grade_service is not None
    assert launch.grade_service.lineitem == platform.lineitem_url("11")
    assert launch.grade_service.lineitems == f"{platform.url}/lineitems"
    assert launch.grade_service.can_post_scores
    assert launch.deep_linking is None


def test_an_instructor_launch_to_an_exercise(platform: TestPlatform, tool: Tool) -> None:
    login = tool.nonces.issue()
    token = platform.id_token(
        login.nonce,
        **{
            claims.ROLES: [INSTRUCTOR],
            claims.CUSTOM: {"exercise": "talker_listener", "attempts": 3},
            claims.AGS_ENDPOINT: None,
            "name": None,
            "email": None,
        },
    )
    launch = tool.validator.validate(token, login.state)
    assert launch.is_instructor
    assert (launch.lesson, launch.exercise) == (None, "talker_listener")
    assert launch.custom["attempts"] == "3"  # custom values read as text
    assert (launch.name, launch.email, launch.grade_service) == (None, None, None)


def test_several_audiences_with_our_azp_pass(platform: TestPlatform, tool: Tool) -> None:
    login = tool.nonces.issue()
    token = platform.id_token(login.nonce, aud=["other-tool", CLIENT_ID], azp=CLIENT_ID)
    assert tool.validator.validate(token, login.state).user_id == "learner-42"


def test_platform_keys_are_cached_and_refetched_once_for_a_new_kid(platform: TestPlatform) -> None:
    now = [0.0]
    nonces = NonceStore()
    validator = LaunchValidator(
        Registrations([platform.registration()]),
        nonces,
        platform_keys=lambda url: PlatformKeys(url, clock=lambda: now[0]),
    )

    def launch() -> str:
        login = nonces.issue()
        return validator.validate(platform.id_token(login.nonce), login.state).user_id

    launch()
    launch()
    assert platform.jwks_fetches == 1  # cached
    now[0] += 1
    platform.rotate_key()
    # Within seconds of the last fetch an unknown kid is refused without asking again:
    # forged tokens with made-up kids cannot make us hammer the LMS.
    with pytest.raises(LaunchRejected, match="has no key with kid"):
        launch()
    assert platform.jwks_fetches == 1
    now[0] += 10
    assert launch() == "learner-42"  # the new key, fetched once
    assert launch() == "learner-42"
    assert platform.jwks_fetches == 2


def _other_key() -> rsa.RSAPrivateKey:
    return rsa.generate_private_key(public_exponent=65537, key_size=2048)


BAD_LAUNCHES = {
    "forged signature": (
        {"key": "other"},
        "signature does not match the platform's key: it was forged or altered",
    ),
    "wrong issuer": (
        {"iss": "https://lms.elsewhere.edu"},
        "the issuer 'https://lms.elsewhere.edu' is not a platform registered with this tool",
    ),
    "wrong audience": (
        {"aud": "another-tool"},
        "meant for audience 'another-tool', not for this tool's client id",
    ),
    "several audiences, no azp": (
        {"aud": [CLIENT_ID, "another-tool"]},
        "several audiences but no authorized party",
    ),
    "azp of another tool": (
        {"aud": [CLIENT_ID, "another-tool"], "azp": "another-tool"},
        "authorized party \\(azp\\) is 'another-tool'",
    ),
    "expired": (
        {"exp": int(time.time()) - 3600, "iat": int(time.time()) - 3900},
        "the id_token expired at",
    ),
    "issued in the future": (
        {"iat": int(time.time()) + 3600, "exp": int(time.time()) + 3900},
        "issued in the future",
    ),
    "unknown deployment": (
        {claims.DEPLOYMENT_ID: "deployment-unknown"},
        "deployment 'deployment-unknown' of .* is not registered with this tool",
    ),
    "wrong version": ({claims.VERSION: "1.1"}, "LTI version '1.1'; this tool speaks 1.3.0"),
    "unknown message type": (
        {claims.MESSAGE_TYPE: "LtiSubmissionReviewRequest"},
        "message type 'LtiSubmissionReviewRequest' is not one this tool handles",
    ),
    "no user": ({"sub": None}, "lacks the 'sub' claim"),
    "no resource link": ({claims.RESOURCE_LINK: None}, "has no resource link id"),
    "deep linking without a return URL": (
        {claims.MESSAGE_TYPE: claims.DEEP_LINKING_REQUEST},
        "has no deep_link_return_url",
    ),
}


@pytest.mark.parametrize("case", BAD_LAUNCHES, ids=list(BAD_LAUNCHES))
def test_a_bad_launch_is_refused_with_its_own_sentence(
    platform: TestPlatform, tool: Tool, case: str
) -> None:
    changes, sentence = BAD_LAUNCHES[case]
    login = tool.nonces.issue()
    key = _other_key() if changes.pop("key", None) == "other" else None
    token = platform.id_token(login.nonce, key=key, **changes)
    changes.update({"key": "other"} if key else {})  # leave the shared table as it was
    with pytest.raises(LaunchRejected, match=sentence):
        tool.validator.validate(token, login.state)
    # A refused launch spends nothing: the learner's real login still works.
    assert tool.validator.validate(platform.id_token(login.nonce), login.state).user_id


def test_a_replayed_launch_is_refused(platform: TestPlatform, tool: Tool) -> None:
    login = tool.nonces.issue()
    token = platform.id_token(login.nonce)
    tool.validator.validate(token, login.state)
    with pytest.raises(LaunchRejected, match="nonce was already used: this launch is a replay"):
        tool.validator.validate(token, login.state)


def test_a_launch_without_our_login_is_refused(platform: TestPlatform, tool: Tool) -> None:
    with pytest.raises(LaunchRejected, match="state was not issued by this tool's login step"):
        tool.validator.validate(platform.id_token("a-nonce-we-never-issued"), "made-up-state")
    login = tool.nonces.issue()
    with pytest.raises(LaunchRejected, match="nonce is not the one this tool's login step issued"):
        tool.validator.validate(platform.id_token("another-nonce"), login.state)


def test_an_old_login_is_forgotten(platform: TestPlatform) -> None:
    now = [1000.0]
    nonces = NonceStore(login_ttl_sec=600, clock=lambda: now[0])
    validator = LaunchValidator(Registrations([platform.registration()]), nonces)
    login = nonces.issue()
    now[0] += 601
    with pytest.raises(LaunchRejected, match="more than a few minutes old"):
        validator.validate(platform.id_token(login.nonce), login.state)


def test_garbage_and_unsigned_tokens_are_refused(platform: TestPlatform, tool: Tool) -> None:
    login = tool.nonces.issue()
    with pytest.raises(LaunchRejected, match="not a readable JWT"):
        tool.validator.validate("not.a.jwt", login.state)
    import jwt

    unsigned = jwt.encode(platform.launch_claims(login.nonce), key=None, algorithm="none")
    with pytest.raises(LaunchRejected, match="signed with 'none'; LTI 1.3 launches must be RS256"):
        tool.validator.validate(unsigned, login.state)
