"""The "ROS 2 Classroom" launcher entry of a Jupyter server (jupyter-server-proxy).

On any Jupyter server or JupyterHub single-user server where the project is
installed, jupyter-server-proxy finds this function through the
``jupyter_serverproxy_servers`` entry point (pyproject.toml). On the first
request to ``<base>/ros2-classroom/`` it starts this learner's dashboard on a
free loopback port and forwards the page and its websockets to it, behind the
hub's login; every path the dashboard's pages use is relative, so any base
path works.

Another user of the same machine could still reach that loopback port
directly, past the hub. So the dashboard gets a fresh random access token
(its usual gate, ``app.access``) which only the proxy knows: the proxy adds it
to every request as a header, and a request that comes any other way gets
401. The token never appears in a URL.

Progress, exercise code and bags go to ``~/ros2-classroom/`` (the learner's
own home, which a hub keeps across sessions). ``ROS_DOMAIN_ID`` comes from the
single-user server's environment, as a spawner sets it; under a container
spawner every learner has a loopback of their own and domain 0 is fine.
"""

from __future__ import annotations

import sys
from pathlib import Path

from app.access import TOKEN_ENV, TOKEN_HEADER, new_token

NAME = "ros2-classroom"
TITLE = "ROS 2 Classroom"
ICON = Path(__file__).resolve().parent / "icon.svg"
START_TIMEOUT_SEC = 90  # a cold start on a busy 2-core host (imports, first DDS discovery)


def learner_home() -> Path:
    return Path.home() / NAME


def setup_ros2_classroom() -> dict[str, object]:
    """jupyter-server-proxy's description of the dashboard (called once per Jupyter server)."""
    token = new_token()
    return {
        "command": [
            sys.executable,
            "-m",
            "app",
            "serve",
            "--host",
            "127.0.0.1",
            "--port",
            "{port}",
            "--progress-dir",
            str(learner_home() / "progress"),
        ],
        "environment": {TOKEN_ENV: token, "PYTHONUNBUFFERED": "1"},
        "request_headers_override": {TOKEN_HEADER: token},
        "timeout": START_TIMEOUT_SEC,
        "absolute_url": False,  # the dashboard sees "/", whatever the hub's base path
        "new_browser_tab": True,
        # In the launcher's first section: jupyter-server-proxy draws the icon only there
        # (a "ROS 2" section of its own showed a blank tile at the bottom of the launcher).
        "launcher_entry": {"title": TITLE, "icon_path": str(ICON), "enabled": True},
    }
