"""JupyterHub on one server with ROS 2 Classroom: `jupyterhub -f deploy/jupyterhub_config.py`.

Run it from the project's venv (`make setup` installs jupyterhub, JupyterLab,
the proxy and the project). Each learner logs in with their system account
(PAM) and gets their own single-user server running as that account
(JupyterHub's LocalProcessSpawner). Every learner gets a ROS domain id of
their own from the spawner's pool, so nobody sees another's nodes on this
machine's loopback.

Which single-user server, chosen by $CLASSROOM_SINGLEUSER:

  dashboard (default, recommended for a class): the dashboard itself is the
      learner's server at /user/<name>/, logging them in with the hub's OAuth
      (app/hub/singleuser_auth.py). The smallest footprint: about the memory
      of a `classroom` learner (bench/results/hub_spawn.md).
  lab: JupyterLab at /user/<name>/lab; its launcher's "ROS 2 Classroom" tile
      opens the dashboard at /user/<name>/ros2-classroom/ in a new tab
      (jupyter-server-proxy, app/hub/server_proxy.py). Learners also get
      notebooks, terminals and a file browser, for ~105 MB more each.

Teachers are hub admins and members of the hub group named by
$CLASSROOM_TEACHERS_GROUP (default "teachers"); they open the teacher's page
at /services/classroom-teacher/. Learners' dashboards send their progress
there over HTTP with their own hub API token.

Settings through the environment (all optional):
  CLASSROOM_HUB_BIND_URL      public address (default http://:8000)
  CLASSROOM_HUB_ADMINS        comma-separated admin users
  CLASSROOM_TEACHERS          comma-separated members of the teachers group
  CLASSROOM_TEACHERS_GROUP    the teachers' group name (default teachers)
  CLASSROOM_TEACHER_PORT      the teacher service's loopback port (default 10101)
  CLASSROOM_SAME_ACCOUNT=1    no system user per learner: every server runs as
                              the hub's account with its own HOME (trying it out)
  CLASSROOM_SINGLEUSER        dashboard (default) or lab, see above
  CLASSROOM_LTI_URL, CLASSROOM_LTI_DIR
                              the teacher service as the LMS's LTI tool; with
                              deploy/lti_tool_config.py (docs/deploy/lti.md)
"""

import os
import sys
from pathlib import Path

c = get_config()  # type: ignore[name-defined]  # noqa: F821 (JupyterHub's config loader)

ROOT = Path(__file__).resolve().parent.parent
SERVICE = "classroom-teacher"
TEACHERS = os.environ.get("CLASSROOM_TEACHERS_GROUP", "teachers")
SERVICE_PORT = int(os.environ.get("CLASSROOM_TEACHER_PORT", "10101"))
SERVICE_URL = f"http://127.0.0.1:{SERVICE_PORT}"
SINGLEUSER = os.environ.get("CLASSROOM_SINGLEUSER", "dashboard")
LTI_SETTINGS = ("CLASSROOM_LTI_URL", "CLASSROOM_LTI_DIR")  # passed on to the teacher service


def _names(var):
    return {n.strip() for n in os.environ.get(var, "").split(",") if n.strip()}


c.JupyterHub.bind_url = os.environ.get("CLASSROOM_HUB_BIND_URL", "http://:8000")
# configurable-http-proxy, installed from npm by `make setup` (app/hub/proxy/).
c.ConfigurableHTTPProxy.command = [
    str(ROOT / "app" / "hub" / "proxy" / "node_modules" / ".bin" / "configurable-http-proxy")
]

# Learners: system accounts; a single-user server from this venv.
c.Authenticator.admin_users = _names("CLASSROOM_HUB_ADMINS")
c.Authenticator.allow_all = True  # every account that logs in; narrow with allowed_users
if os.environ.get("CLASSROOM_SAME_ACCOUNT") == "1":
    c.JupyterHub.spawner_class = "app.hub.spawner.ClassroomLocalSpawner"
else:
    c.JupyterHub.spawner_class = "app.hub.spawner.ClassroomSystemUserSpawner"
if SINGLEUSER == "dashboard":
    c.Spawner.cmd = [sys.executable, "-m", "app", "serve", "--jupyterhub"]
elif SINGLEUSER == "lab":
    c.Spawner.cmd = [sys.executable, "-m", "jupyterhub.singleuser"]
    c.Spawner.default_url = "/lab"  # the launcher, with its "ROS 2 Classroom" tile
else:
    raise ValueError(f"CLASSROOM_SINGLEUSER must be dashboard or lab, not {SINGLEUSER!r}")
c.Spawner.start_timeout = 120
c.Spawner.http_timeout = 120
c.Spawner.environment = {
    # Where each learner's dashboard sends its progress (with its own hub token).
    "CLASSROOM_TEACHER_URL": f"{SERVICE_URL}/services/{SERVICE}/",
}

# Teachers: the group, allowed into the teacher service; the service may read users.
c.JupyterHub.load_groups = {TEACHERS: {"users": sorted(_names("CLASSROOM_TEACHERS"))}}
c.JupyterHub.load_roles = [
    {
        "name": "classroom-teachers",
        "description": "Open the ROS 2 Classroom teacher's page",
        "groups": [TEACHERS],
        "scopes": [f"access:services!service={SERVICE}"],
    },
]
c.JupyterHub.services = [
    {
        "name": SERVICE,
        "display": True,  # listed on the hub's home page for those who may open it
        "url": SERVICE_URL,
        "command": [sys.executable, "-m", "app.hub.teacher_service"],
        "oauth_no_confirm": True,
        "cwd": str(ROOT),
        # The LMS's LTI tool, when deploy/lti_tool_config.py is loaded (docs/deploy/lti.md).
        "environment": {k: v for k, v in os.environ.items() if k in LTI_SETTINGS},
    }
]
