"""Inside JupyterHub: log in the person an LTI launch brought, and send them on.

The teacher service checks the LMS's launch (app/hub/lti_service.py) and
sends the browser to ``/hub/lti-handoff?ticket=...``. This page trades the
one-time ticket with the service (a POST to its ``lti/handoff``, over the
service's internal address), logs the browser in as the hub user the
service names (``lti-`` and a hash of the LMS's issuer and user id), puts
teachers in the teachers' group, and redirects to the learner's server or to
the teacher's page.

``LtiHandoffMixin`` adds this to any authenticator; ``ClassroomLtiAuthenticator``
is it on top of JupyterHub's PAM login, so the school's own accounts (admins,
teachers) still log in as before. deploy/lti_tool_config.py turns it on.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING
from urllib.parse import urlencode, urlsplit

from jupyterhub.auth import Authenticator, PAMAuthenticator
from jupyterhub.handlers import BaseHandler
from jupyterhub.utils import maybe_future, url_path_join
from tornado import web
from tornado.httpclient import AsyncHTTPClient, HTTPClientError
from traitlets import Unicode

if TYPE_CHECKING:
    from collections.abc import Awaitable, Mapping

    from jupyterhub.app import JupyterHub
    from jupyterhub.orm import User as OrmUser
    from jupyterhub.user import User

HANDOFF_PAGE = "/lti-handoff"  # the hub adds its own prefix: /hub/lti-handoff
# app.lti.learners.NAME_PREFIX (that module needs PyJWT; this one runs inside the hub).
LTI_USER_PREFIX = "lti-"
TICKET_FIELD = "lti_ticket"


class LtiHandoffHandler(BaseHandler):
    async def get(self) -> None:
        ticket = self.get_argument("ticket", "")
        authenticated = await self.authenticate({TICKET_FIELD: ticket})
        if not authenticated:
            raise web.HTTPError(
                403,
                "This link from your course has expired or was already used: "
                "open the activity again from the LMS.",
            )
        user = await self.auth_to_user(authenticated)
        self.set_login_cookie(user)
        group = self.authenticator.lti_teachers_group
        if authenticated.get("lti_teacher") and group and not self.authenticator.manage_groups:
            user.sync_groups(sorted({g.name for g in user.groups} | {group}))
        next_url = str(authenticated.get("lti_next") or url_path_join(self.hub.base_url, "home"))
        parts = urlsplit(next_url)
        if parts.scheme or parts.netloc or not next_url.startswith("/"):
            next_url = url_path_join(self.hub.base_url, "home")  # only paths on this hub
        self.log.info("LTI: %s logged in from the LMS, on to %s", user.name, next_url)
        self.redirect(next_url)


class LtiHandoffMixin(Authenticator):
    """Adds the LTI handoff page to an authenticator: ``class X(LtiHandoffMixin, TheirAuth)``."""

    lti_service_url = Unicode(
        "http://127.0.0.1:10101/services/classroom-teacher/",
        config=True,
        help="The teacher service's address as the hub reaches it (its internal URL and prefix)",
    )
    lti_teachers_group = Unicode(
        "teachers",
        config=True,
        help="The group an LMS instructor joins at launch (it opens the teacher's page)",
    )

    def get_handlers(self, app: JupyterHub) -> list[tuple[str, type]]:
        return [*super().get_handlers(app), (HANDOFF_PAGE, LtiHandoffHandler)]

    async def authenticate(
        self, handler: web.RequestHandler | None, data: dict[str, str]
    ) -> str | dict[str, object] | None:
        ticket = (data or {}).get(TICKET_FIELD)
        if ticket is None:
            return await maybe_future(super().authenticate(handler, data))
        handoff = await self.redeem(str(ticket))
        if handoff is None:
            return None
        return {
            "name": handoff["name"],
            "lti_next": handoff["next"],
            "lti_teacher": bool(handoff["teacher"]),
        }

    def add_user(self, user: User | OrmUser) -> Awaitable[None] | None:
        if user.name.startswith(LTI_USER_PREFIX):
            # An LMS learner has no system account (PAM's LocalAuthenticator wants one).
            return Authenticator.add_user(self, user)
        return super().add_user(user)

    def check_allowed(
        self, username: str, authentication: Mapping[str, object] | None = None
    ) -> bool | Awaitable[bool]:
        if authentication and "lti_next" in authentication:
            return True  # the LMS's course decides who launches; the service checked the launch
        return super().check_allowed(username, authentication)

    async def redeem(self, ticket: str) -> dict[str, object] | None:
        """Whom the service says this ticket logs in, or None (the log says why)."""
        url = url_path_join(self.lti_service_url, "lti/handoff")
        try:
            answer = await AsyncHTTPClient().fetch(
                url, method="POST", body=urlencode({"ticket": ticket}), request_timeout=10
            )
            handoff = json.loads(answer.body)
        except HTTPClientError as error:
            body = error.response.body.decode("utf-8", "replace") if error.response else ""
            self.log.warning("LTI: the service refused a handoff ticket: %s %s", error, body)
            return None
        except (OSError, ValueError) as error:
            self.log.warning("LTI: the teacher service at %s did not answer: %s", url, error)
            return None
        if not isinstance(handoff, dict) or not isinstance(handoff.get("name"), str):
            self.log.warning("LTI: the service's handoff answer has no user: %r", handoff)
            return None
        return handoff


class ClassroomLtiAuthenticator(LtiHandoffMixin, PAMAuthenticator):
    """PAM for the school's accounts, and the LTI handoff for everyone the LMS launches."""
