"""Deep Linking 2.0: the teacher picks lessons or exercises, we hand them to the LMS.

Each picked activity becomes an ``ltiResourceLink`` whose custom parameters
name the lesson or exercise and its points, with a line item so the LMS makes
the grade column at once. The response is a JWT signed by the tool key, carried back
by the browser in an auto-submitting form.
"""

from __future__ import annotations

import html
import secrets
import time
import urllib.parse
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Literal

from app.jsonish import JSONObject
from app.lti import claims
from app.lti.keys import ToolKeys
from app.lti.launch import Launch

RESPONSE_LIFE_SEC = 600
RESOURCE_LINK_TYPE = "ltiResourceLink"
SCORE_MAXIMUM_PARAM = "score_maximum"  # the custom parameter with the activity's points


class DeepLinkingError(ValueError):
    """The LMS's request does not allow what was picked (wrong type, too many items)."""


@dataclass(frozen=True)
class Activity:
    """One lesson or exercise a teacher picked, with the points it is worth."""

    kind: Literal["lesson", "exercise"]
    slug: str
    title: str
    score_maximum: float
    text: str = ""

    def content_item(self, launch_url: str) -> JSONObject:
        item: JSONObject = {
            "type": RESOURCE_LINK_TYPE,
            "title": self.title,
            "url": launch_url,
            # The points ride along, so the learner's launch says what a score is out of.
            "custom": {self.kind: self.slug, SCORE_MAXIMUM_PARAM: f"{self.score_maximum:g}"},
            "lineItem": {
                "scoreMaximum": self.score_maximum,
                "label": self.title,
                # Stable across courses, so the gradebook can tell which activity a column is.
                "resourceId": f"{self.kind}:{self.slug}",
            },
        }
        if self.text:
            item["text"] = self.text
        return item


MAX_POINTS = 1000.0


def picks_from_form(
    form: Mapping[str, Sequence[str]], catalog: Sequence[Activity]
) -> list[Activity]:
    """What the teacher ticked on the picker (app/lti/pages.py), each with the points typed.

    Only activities of ``catalog`` can be picked: a forged form names nothing else.
    """
    known = {f"{a.kind}:{a.slug}": a for a in catalog}
    picked: list[Activity] = []
    for value in form.get("pick", ()):
        activity = known.get(value)
        if activity is None:
            raise DeepLinkingError(f"{value!r} is not a lesson or exercise of this course")
        typed = (form.get(f"points-{value}") or [f"{activity.score_maximum:g}"])[0]
        try:
            points = float(typed)
        except ValueError:
            raise DeepLinkingError(f"the points for {activity.title!r} are not a number") from None
        if not 0 < points <= MAX_POINTS:
            raise DeepLinkingError(
                f"the points for {activity.title!r} must be above 0 and at most {MAX_POINTS:g}"
            )
        picked.append(replace(activity, score_maximum=points))
    if not picked:
        raise DeepLinkingError("nothing was picked: tick a lesson or an exercise")
    return picked


def deep_linking_response(
    launch: Launch,
    picked: Sequence[Activity],
    keys: ToolKeys,
    launch_url: str,
    *,
    message: str | None = None,
    clock: Callable[[], float] = time.time,
) -> str:
    """The signed LtiDeepLinkingResponse for a deep-linking ``launch``."""
    settings = launch.deep_linking
    if settings is None:
        raise DeepLinkingError("this launch is not a deep-linking request")
    if picked and settings.accept_types and RESOURCE_LINK_TYPE not in settings.accept_types:
        raise DeepLinkingError(
            f"the LMS accepts only {', '.join(settings.accept_types)} here, not LTI links"
        )
    if len(picked) > 1 and not settings.accept_multiple:
        raise DeepLinkingError("the LMS accepts one activity here; pick one")
    now = int(clock())
    body: JSONObject = {
        "iss": launch.registration.client_id,
        "aud": launch.registration.issuer,
        "iat": now,
        "exp": now + RESPONSE_LIFE_SEC,
        "nonce": secrets.token_urlsafe(16),
        claims.DEPLOYMENT_ID: launch.deployment_id,
        claims.MESSAGE_TYPE: claims.DEEP_LINKING_RESPONSE,
        claims.VERSION: claims.LTI_VERSION,
        claims.CONTENT_ITEMS: [activity.content_item(launch_url) for activity in picked],
    }
    if settings.data is not None:
        body[claims.DEEP_LINKING_DATA] = settings.data
    if message:
        body[claims.DEEP_LINKING_MESSAGE] = message
    return keys.sign(body)


def auto_submit_form(return_url: str, response_jwt: str) -> str:
    """A page that posts ``response_jwt`` to the LMS at once (a button if scripts are off)."""
    if urllib.parse.urlsplit(return_url).scheme not in ("https", "http"):
        raise DeepLinkingError(f"the deep-linking return URL {return_url!r} is not a web address")
    action, value = html.escape(return_url, quote=True), html.escape(response_jwt, quote=True)
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8"><title>Back to the course</title></head>\n'
        "<body>\n"
        f'<form id="lti-return" method="post" action="{action}">\n'
        f'<input type="hidden" name="JWT" value="{value}">\n'
        '<noscript><button type="submit">Back to the course</button></noscript>\n'
        "</form>\n"
        '<script>document.getElementById("lti-return").submit();</script>\n'
        "</body></html>\n"
    )
