"""The classroom as the LMS's LTI 1.3 tool, with grades sent back: add to jupyterhub_config.py.

At the end of deploy/jupyterhub_config.py: ``load_subconfig("deploy/lti_tool_config.py")``.
The teacher service (app/hub/teacher_service.py) then serves the LTI
addresses under /services/classroom-teacher/lti/ and sends each learner's
finished lessons and passed exercises to the LMS's gradebook, and shows
teachers what was sent and what waits at /services/classroom-teacher/gradebook;
the hub logs in whoever the LMS launched (app/hub/lti_login.py) and keeps
PAM for the school's own accounts. docs/deploy/lti.md is the whole story.

Settings through the environment:
  CLASSROOM_LTI_URL   the service's public address as the LMS reaches it, e.g.
                      https://hub.example.edu/services/classroom-teacher
                      (what `ros2-classroom lti config --base-url` was given)
  CLASSROOM_LTI_DIR   the tool's folder: key, platforms.toml, launches, outbox
                      (default var/lti in the project; only the service reads it)

This replaces deploy/lti_config.py (jupyterhub-ltiauthenticator), which logs
learners in from the LMS but sends no grade back: use one or the other.
"""

import os

c = get_config()  # type: ignore[name-defined]  # noqa: F821 (JupyterHub's config loader)

SERVICE = "classroom-teacher"
PORT = int(os.environ.get("CLASSROOM_TEACHER_PORT", "10101"))
if not os.environ.get("CLASSROOM_LTI_URL", "").strip():
    # jupyterhub_config.py hands CLASSROOM_LTI_URL and CLASSROOM_LTI_DIR to the service.
    raise ValueError(
        "set CLASSROOM_LTI_URL to the teacher service's public address, e.g. "
        f"https://hub.example.edu/services/{SERVICE}"
    )

c.JupyterHub.authenticator_class = "app.hub.lti_login.ClassroomLtiAuthenticator"
# The hub trades a launch's ticket with the service over loopback, not through the proxy.
c.ClassroomLtiAuthenticator.lti_service_url = f"http://127.0.0.1:{PORT}/services/{SERVICE}/"
c.ClassroomLtiAuthenticator.lti_teachers_group = os.environ.get(
    "CLASSROOM_TEACHERS_GROUP", "teachers"
)
# LMS learners are hub users named lti-<hash>: no system account has that name, so
# each learner's server runs as the hub's account with a HOME of its own (on
# Kubernetes, each learner has a pod instead: leave the spawner to z2jh there).
c.JupyterHub.spawner_class = "app.hub.spawner.ClassroomLocalSpawner"
