"""A real JupyterHub on loopback for tests and bench/hub_spawn.py: deploy/'s config, made local.

The hub loads deploy/jupyterhub_config.py itself (so the operator's file is
what runs), then this module's few overrides: loopback ports, a state folder,
jupyterhub's DummyAuthenticator with one password (no system accounts here),
and ClassroomLocalSpawner (each learner's server as this account, with its
own HOME and ROS domain id), in either single-user mode (``singleuser``:
"lab", JupyterLab with the launcher; "dashboard", the lean mode).
configurable-http-proxy comes from npm (app/hub/proxy, `make setup`).
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path
from typing import Any

import psutil

from app import PROJECT_ROOT

DEPLOY_CONFIG = PROJECT_ROOT / "deploy" / "jupyterhub_config.py"
PROXY = PROJECT_ROOT / "app" / "hub" / "proxy" / "node_modules" / ".bin" / "configurable-http-proxy"
PASSWORD = "classroom-test-password"
ADMIN_TOKEN = "hub-admin-test-token-0123456789abcdef"
TEACHERS_GROUP = "teachers"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


OVERRIDES = """
import json
c = get_config()
load_subconfig({deploy!r})
o = json.loads({overrides!r})
c.JupyterHub.bind_url = o["bind_url"]
c.JupyterHub.hub_bind_url = o["hub_bind_url"]
c.ConfigurableHTTPProxy.api_url = o["proxy_api_url"]
c.JupyterHub.db_url = o["db_url"]
c.JupyterHub.cookie_secret_file = o["cookie_secret_file"]
c.JupyterHub.pid_file = o["pid_file"]
c.ConfigurableHTTPProxy.pid_file = o["proxy_pid_file"]
c.JupyterHub.authenticator_class = "dummy"
c.DummyAuthenticator.password = o["password"]
c.Authenticator.allow_all = False
c.Authenticator.allowed_users = set(o["users"])
c.Authenticator.admin_users = set(o["admins"])
c.JupyterHub.spawner_class = "app.hub.spawner.ClassroomLocalSpawner"
c.ClassroomLocalSpawner.home_dir_template = o["homes"] + "/{{username}}"
c.ClassroomLocalSpawner.first_domain_id = o["first_domain_id"]
c.Spawner.environment["PYTHONPATH"] = o["pythonpath"]
c.Spawner.environment["JUPYTERHUB_ACTIVITY_INTERVAL"] = str(o["activity_interval"])
c.JupyterHub.load_groups = {{o["teachers_group"]: {{"users": o["teachers"]}}}}
c.JupyterHub.services.append({{"name": "test-admin", "api_token": o["admin_token"]}})
c.JupyterHub.load_roles.append(
    {{
        "name": "test-admin",
        "services": ["test-admin"],
        "scopes": ["admin:users", "admin:servers", "read:users", "access:servers"],
    }}
)
c.JupyterHub.last_activity_interval = 3600
"""


class LocalHub:
    """``jupyterhub`` as a child process in a session of its own; ``stop`` ends all it started."""

    def __init__(
        self,
        state_dir: Path,
        env: dict[str, str],
        *,
        learners: list[str],
        teachers: list[str],
        admins: list[str] = (),  # type: ignore[assignment]
        first_domain_id: int = 60,
        log_path: Path | None = None,
        singleuser: str = "lab",
        activity_interval: int = 300,
    ) -> None:
        state_dir.mkdir(parents=True, exist_ok=True)
        self.state_dir = state_dir
        self.homes = state_dir / "homes"
        self.port = free_port()
        self.service_port = free_port()
        self.base = f"http://127.0.0.1:{self.port}"
        overrides = {
            "bind_url": self.base,
            "hub_bind_url": f"http://127.0.0.1:{free_port()}",
            "proxy_api_url": f"http://127.0.0.1:{free_port()}",
            "db_url": f"sqlite:///{state_dir / 'jupyterhub.sqlite'}",
            "cookie_secret_file": str(state_dir / "cookie_secret"),
            "pid_file": str(state_dir / "hub.pid"),
            "proxy_pid_file": str(state_dir / "proxy.pid"),
            "password": PASSWORD,
            "users": [*learners, *teachers, *admins],
            "admins": list(admins),
            "teachers": list(teachers),
            "teachers_group": TEACHERS_GROUP,
            "homes": str(self.homes),
            "first_domain_id": first_domain_id,
            "pythonpath": str(PROJECT_ROOT),
            "admin_token": ADMIN_TOKEN,
            "activity_interval": activity_interval,
        }
        self.lean = singleuser == "dashboard"
        config = state_dir / "jupyterhub_config.py"
        config.write_text(
            OVERRIDES.format(deploy=str(DEPLOY_CONFIG), overrides=json.dumps(overrides))
        )
        self.log_path = log_path or state_dir / "jupyterhub.log"
        self._log = open(self.log_path, "wb")
        hub_env = {
            **env,
            "PYTHONPATH": str(PROJECT_ROOT),
            "CLASSROOM_TEACHER_PORT": str(self.service_port),
            "CLASSROOM_SINGLEUSER": singleuser,
            "PATH": f"{Path(sys.executable).parent}:{env.get('PATH', '/usr/bin:/bin')}",
        }
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "jupyterhub", "-f", str(config)],
            cwd=state_dir,
            env=hub_env,
            stdout=self._log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )

    # -- waiting and asking ------------------------------------------------------------

    def wait_ready(self, timeout: float = 60.0) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"jupyterhub exited early:\n{self.log_tail()}")
            try:
                if self.api("GET", "/hub/api/")[0] == 200:
                    return
            except OSError:
                pass
            time.sleep(0.3)
        raise RuntimeError(f"jupyterhub did not answer in {timeout:.0f} s:\n{self.log_tail()}")

    def log_tail(self, chars: int = 4000) -> str:
        if not self._log.closed:
            self._log.flush()
        return self.log_path.read_text(errors="replace")[-chars:]

    def api(
        self,
        method: str,
        path: str,
        body: Any = None,
        token: str | None = ADMIN_TOKEN,
        raw: bytes | None = None,
        timeout: float = 15.0,
    ) -> tuple[int, Any]:
        """One request to the hub's public address; JSON answers decoded."""
        data = raw if raw is not None else (json.dumps(body).encode() if body is not None else None)
        headers = {"Content-Type": "application/json"}
        if token:
            headers["Authorization"] = f"token {token}"
        request = urllib.request.Request(self.base + path, data, headers, method=method)
        try:
            with urllib.request.urlopen(request, timeout=timeout) as answer:
                status, text = answer.status, answer.read()
        except urllib.error.HTTPError as error:
            status, text = error.code, error.read()
        try:
            return status, json.loads(text)
        except ValueError:
            return status, text.decode(errors="replace")

    def spawn(self, user: str) -> None:
        """Ask the hub to start ``user``'s server (the admin API, as the benchmark does)."""
        # The hub answers once the spawn is done or 10 s have passed (slow_spawn_timeout);
        # with a class arriving at once on busy cores that answer alone took over 15 s.
        status, body = self.api("POST", f"/hub/api/users/{user}/server", timeout=120.0)
        if status not in (201, 202, 400):  # 400: already running
            raise RuntimeError(f"spawning {user}: {status} {body}")

    def server_ready(self, user: str) -> bool:
        status, model = self.api("GET", f"/hub/api/users/{user}")
        return status == 200 and bool(model.get("servers", {}).get("", {}).get("ready"))

    # -- the processes it started --------------------------------------------------------

    def single_user_servers(self) -> dict[str, psutil.Process]:
        """user name -> their single-user server process (its environment says whose)."""
        found = {}
        for proc in self._descendants():
            try:
                cmd = proc.cmdline()
                if "jupyterhub.singleuser" in cmd or "--jupyterhub" in cmd:
                    found[proc.environ().get("JUPYTERHUB_USER", "?")] = proc
            except psutil.Error:
                continue
        return found

    def dashboards(self) -> dict[str, psutil.Process]:
        """user name -> their dashboard: the server itself (lean), or what its proxy started."""
        if self.lean:
            return self.single_user_servers()
        found = {}
        for user, server in self.single_user_servers().items():
            try:
                for child in server.children(recursive=True):
                    cmd = child.cmdline()
                    if "-m" in cmd and "app" in cmd and "serve" in cmd:
                        found[user] = child
            except psutil.Error:
                continue
        return found

    def _descendants(self) -> list[psutil.Process]:
        try:
            return psutil.Process(self.proc.pid).children(recursive=True)
        except psutil.NoSuchProcess:
            return []

    def stop(self) -> list[psutil.Process]:
        """SIGTERM: the hub stops every server (each stops its dashboard and nodes).

        Returns whatever it started that still lived 30 s later (then killed)."""
        started = self._descendants()
        try:
            os.killpg(self.proc.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        try:
            self.proc.wait(30)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        _gone, alive = psutil.wait_procs(started, timeout=30)
        for proc in alive:
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                proc.kill()
        self._log.close()
        return alive


def log_in(page: Any, login_url: str, user: str) -> None:
    """Sign ``user`` in on the hub's login page, as a person does (a Playwright page).

    The login page is a page's first sight: on a loaded 2-core machine its
    Sign in button took more than Playwright's 30 s default to be ready
    (rehearsal ci72, load 16), so it gets the first-load wait of every page.
    """
    from tests.browser.helpers import open_page  # playwright: for browser tests only

    open_page(page, login_url, "button", "Sign in")
    page.get_by_label("Username").fill(user)
    page.get_by_label("Password").fill(PASSWORD)
    with page.expect_navigation(wait_until="commit"):
        page.get_by_role("button", name="Sign in").click()
