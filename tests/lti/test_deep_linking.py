"""Deep Linking 2.0: a teacher's picks go back to the LMS as a JWT it can verify."""

from __future__ import annotations

import html
import re

import jwt
import pytest

from app.lti import claims
from app.lti.deep_linking import (
    Activity,
    DeepLinkingError,
    auto_submit_form,
    deep_linking_response,
)
from app.lti.keys import ToolKeys
from app.lti.launch import Launch, LaunchValidator
from app.lti.nonces import NonceStore
from app.lti.registration import Registrations
from app.lti.routes import ToolUrls
from tests.lti.platform import CLIENT_ID, DEPLOYMENT_ID, TestPlatform

URLS = ToolUrls.from_base("https://tool.example.edu/classroom")
PICKED = [
    Activity("lesson", "05_topics", "Topics: publishers and subscribers", 10),
    Activity("exercise", "talker_listener", "Exercise: talker & listener", 5, text="Graded live"),
]


def _deep_linking_launch(platform: TestPlatform, **settings: object) -> Launch:
    nonces = NonceStore()
    login = nonces.issue()
    values = {
        "deep_link_return_url": f"{platform.url}/deep-link-return?course=101",
        "accept_types": ["ltiResourceLink"],
        "accept_presentation_document_targets": ["iframe", "window"],
        "accept_multiple": True,
        "data": "opaque-platform-data",
        **settings,
    }
    token = platform.id_token(
        login.nonce,
        **{
            claims.MESSAGE_TYPE: claims.DEEP_LINKING_REQUEST,
            claims.DEEP_LINKING_SETTINGS: values,
            claims.RESOURCE_LINK: None,
            claims.AGS_ENDPOINT: None,
            claims.ROLES: ["http://purl.imsglobal.org/vocab/lis/v2/membership#Instructor"],
        },
    )
    validator = LaunchValidator(Registrations([platform.registration()]), nonces)
    return validator.validate(token, login.state)


def test_the_request_is_read(platform: TestPlatform) -> None:
    launch = _deep_linking_launch(platform)
    assert launch.is_instructor and launch.deep_linking is not None
    assert launch.deep_linking.return_url == f"{platform.url}/deep-link-return?course=101"
    assert launch.deep_linking.accept_types == ("ltiResourceLink",)
    assert launch.deep_linking.accept_multiple
    assert launch.deep_linking.data == "opaque-platform-data"


def test_the_response_verifies_with_the_tool_jwks_and_carries_the_picks(
    platform: TestPlatform, tool_keys: ToolKeys
) -> None:
    launch = _deep_linking_launch(platform)
    response = deep_linking_response(launch, PICKED, tool_keys, URLS.launch, message="2 added")
    # As the platform checks it: the tool's published key set, its client id as issuer.
    key = jwt.PyJWKSet.from_dict(tool_keys.public_jwks())[
        jwt.get_unverified_header(response)["kid"]
    ]
    body = jwt.decode(
        response, key, algorithms=["RS256"], audience=platform.issuer, issuer=CLIENT_ID
    )
    assert body[claims.MESSAGE_TYPE] == "LtiDeepLinkingResponse"
    assert body[claims.VERSION] == "1.3.0"
    assert body[claims.DEPLOYMENT_ID] == DEPLOYMENT_ID
    assert body[claims.DEEP_LINKING_DATA] == "opaque-platform-data"
    assert body[claims.DEEP_LINKING_MESSAGE] == "2 added"
    assert body["nonce"] and body["exp"] > body["iat"]
    assert body[claims.CONTENT_ITEMS] == [
        {
            "type": "ltiResourceLink",
            "title": "Topics: publishers and subscribers",
            "url": "https://tool.example.edu/classroom/lti/launch",
            "custom": {"lesson": "05_topics", "score_maximum": "10"},
            "lineItem": {
                "scoreMaximum": 10,
                "label": "Topics: publishers and subscribers",
                "resourceId": "lesson:05_topics",
            },
        },
        {
            "type": "ltiResourceLink",
            "title": "Exercise: talker & listener",
            "url": "https://tool.example.edu/classroom/lti/launch",
            "custom": {"exercise": "talker_listener", "score_maximum": "5"},
            "lineItem": {
                "scoreMaximum": 5,
                "label": "Exercise: talker & listener",
                "resourceId": "exercise:talker_listener",
            },
            "text": "Graded live",
        },
    ]


def test_what_the_platform_does_not_accept_is_refused(
    platform: TestPlatform, tool_keys: ToolKeys
) -> None:
    single = _deep_linking_launch(platform, accept_multiple=False)
    with pytest.raises(DeepLinkingError, match="accepts one activity here"):
        deep_linking_response(single, PICKED, tool_keys, URLS.launch)
    files_only = _deep_linking_launch(platform, accept_types=["file"])
    with pytest.raises(DeepLinkingError, match="accepts only file here"):
        deep_linking_response(files_only, PICKED[:1], tool_keys, URLS.launch)


def test_the_form_posts_the_jwt_back_with_everything_escaped() -> None:
    return_url = 'https://lms.example.edu/return?a=1&b="><script>alert(1)</script>'
    page = auto_submit_form(return_url, 'header.body.sig"<&')
    assert "<script>alert(1)" not in page
    action = re.search(r'<form id="lti-return" method="post" action="([^"]*)">', page)
    assert action is not None and html.unescape(action.group(1)) == return_url
    value = re.search(r'<input type="hidden" name="JWT" value="([^"]*)">', page)
    assert value is not None and html.unescape(value.group(1)) == 'header.body.sig"<&'
    assert 'document.getElementById("lti-return").submit()' in page
    with pytest.raises(DeepLinkingError, match="not a web address"):
        auto_submit_form("javascript:alert(1)", "x")
