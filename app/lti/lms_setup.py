"""What a teacher or LMS administrator pastes into Moodle, Canvas and Open edX.

``ros2-classroom lti config`` prints it. Field names follow each LMS's own
tool set-up form, so the values can be copied line by line.
"""

from __future__ import annotations

import json

from app.jsonish import JSONObject
from app.lti.claims import SCORE_SCOPE
from app.lti.keys import ToolKeys
from app.lti.routes import ToolUrls

TOOL_TITLE = "ROS 2 Classroom"
LINEITEM_SCOPE = "https://purl.imsglobal.org/spec/lti-ags/scope/lineitem"


def canvas_json(urls: ToolUrls) -> JSONObject:
    """Canvas's "Paste JSON" developer key configuration."""
    picker = {"message_type": "LtiDeepLinkingRequest", "target_link_uri": urls.deep_link}
    return {
        "title": TOOL_TITLE,
        "description": "ROS 2 lessons and exercises, graded on a live ROS 2 graph.",
        "oidc_initiation_url": urls.login,
        "target_link_uri": urls.launch,
        "public_jwk_url": urls.jwks,  # a URL, not the key: a key rotation needs no new paste
        "scopes": [SCORE_SCOPE, LINEITEM_SCOPE],
        "extensions": [
            {
                "platform": "canvas.instructure.com",
                "privacy_level": "public",
                "settings": {
                    "placements": [
                        {"placement": "assignment_selection", **picker},
                        {"placement": "link_selection", **picker},
                    ]
                },
            }
        ],
    }


def setup_text(urls: ToolUrls, keys: ToolKeys, registration_url: str = "") -> str:
    """The values to paste into an LMS; ``registration_url``: the dynamic registration's."""
    jwks = json.dumps(keys.public_jwks(), indent=2)
    redirects = "\n".join(f"      {uri}" for uri in urls.redirect_uris)
    by_url = (
        f"""
An LMS that registers tools by URL (LTI Dynamic Registration: Moodle 4.1+,
Canvas, Brightspace) needs only this, and fills in everything below itself:
  Registration URL:           {registration_url}
"""
        if registration_url
        else ""
    )
    return f"""\
{TOOL_TITLE} as an LTI 1.3 tool at {urls.base}
{by_url}
  Login initiation URL:       {urls.login}
  Launch (redirect) URL:      {urls.launch}
  Deep-linking URL:           {urls.deep_link}
  Public keyset (JWKS) URL:   {urls.jwks}
  Key id (kid):               {keys.kid}
  Redirect URIs (all of them):
{redirects}

Moodle (Site administration > Plugins > Activity modules > External tool >
Manage tools > configure a tool manually):
  LTI version                 LTI 1.3
  Tool URL                    {urls.launch}
  Public key type             Keyset URL
  Public keyset               {urls.jwks}
  Initiate login URL          {urls.login}
  Redirection URI(s)          one per line:
{redirects}
  Supports Deep Linking       yes
  Content Selection URL       {urls.deep_link}
  IMS LTI Assignment and Grade Services: Use this service for grade sync only
  Privacy: share the launcher's name and email as your school allows; accept grades

Canvas (Admin > Developer Keys > + Developer Key > LTI Key, method "Paste JSON"):
{json.dumps(canvas_json(urls), indent=2)}

Open edX (Studio: add "lti_consumer" to the course's Advanced Module List, then an
LTI Consumer component):
  LTI Version                 LTI 1.3
  Tool Launch URL             {urls.launch}
  Tool Initiate Login URL     {urls.login}
  Tool Public Key Mode        Keyset URL
  Tool Keyset URL             {urls.jwks}
  Enable LTI Advantage Deep Linking: yes
  Deep Linking Launch URL     {urls.deep_link}
  LTI Assignment and Grades Service: Allow tools to submit grades only (declarative)

The tool's public key as a JWKS, for an LMS that wants the key itself:
{jwks}

From the LMS, note for this tool's registration: the issuer (platform id), the
client id, the deployment id(s), the platform's keyset URL, its authentication
request URL and its access token URL.
"""
