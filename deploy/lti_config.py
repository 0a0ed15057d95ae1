"""Learners and teachers log in from Moodle or Canvas (LTI 1.3): add to jupyterhub_config.py.

    pip install 'jupyterhub-ltiauthenticator>=1.6,<2'

then, at the end of deploy/jupyterhub_config.py (or in Zero to JupyterHub's
hub.extraConfig): ``load_subconfig("deploy/lti_config.py")``. Register
JupyterHub as an LTI 1.3 tool in the LMS (Moodle: Site administration >
Plugins > External tool > Manage tools; Canvas: Admin > Developer Keys > LTI
key), with the login initiation URL ``https://HUB/hub/lti13/oauth_login``, the
redirect URL ``https://HUB/hub/lti13/oauth_callback`` and the public keyset
URL ``https://HUB/hub/lti13/jwks``; the LMS then gives the values below.

Course instructors join the hub's "teachers" group at each login, so they
open the teacher's page (/services/classroom-teacher/); everyone else is a
learner. Values come from the environment so no secret lives in this file.

This sends no grade back to the LMS. deploy/lti_tool_config.py does (the
teacher service as the LMS's LTI tool, with the teacher's gradebook): use
one or the other; docs/deploy/lti.md has the whole story.
"""

import os

c = get_config()  # type: ignore[name-defined]  # noqa: F821 (JupyterHub's config loader)

LMS = os.environ.get("CLASSROOM_LMS_URL", "https://moodle.example.edu")  # or Canvas's
INSTRUCTOR = "http://purl.imsglobal.org/vocab/lis/v2/membership#Instructor"
ROLES_CLAIM = "https://purl.imsglobal.org/spec/lti/claim/roles"

c.JupyterHub.authenticator_class = "ltiauthenticator.lti13.auth.LTI13Authenticator"
# Moodle's endpoints; Canvas: https://canvas.instructure.com/api/lti/authorize_redirect and
# https://canvas.instructure.com/api/lti/security/jwks, issuer https://canvas.instructure.com.
c.LTI13Authenticator.issuer = os.environ.get("CLASSROOM_LTI_ISSUER", LMS)
c.LTI13Authenticator.authorize_url = os.environ.get(
    "CLASSROOM_LTI_AUTHORIZE_URL", f"{LMS}/mod/lti/auth.php"
)
c.LTI13Authenticator.jwks_endpoint = os.environ.get(
    "CLASSROOM_LTI_JWKS_URL", f"{LMS}/mod/lti/certs.php"
)
c.LTI13Authenticator.client_id = {os.environ.get("CLASSROOM_LTI_CLIENT_ID", "replace-me")}
c.LTI13Authenticator.username_key = "email"  # stable and readable in the teacher's table
c.Authenticator.allow_all = True  # whoever the LMS launches into this course
c.Authenticator.enable_auth_state = True  # keeps the launch's claims (roles) for the hook
c.Authenticator.manage_groups = True  # groups come from the hook below


def instructors_teach(authenticator, handler, authentication):
    """An LMS instructor of the course is in the hub's teachers group; a learner is not."""
    claims = authentication.get("auth_state") or {}
    roles = claims.get(ROLES_CLAIM) or claims.get("roles") or []
    authentication["groups"] = ["teachers"] if INSTRUCTOR in roles else []
    return authentication


c.Authenticator.post_auth_hook = instructors_teach
