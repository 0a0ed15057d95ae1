"""A local spawner for one machine account: each learner's server with its own HOME and ROS domain.

JupyterHub's ``LocalProcessSpawner`` runs each single-user server as the
learner's own system user (that is what a one-server deployment should use,
see deploy/jupyterhub_config.py). Tests, benchmarks and a teacher trying the
hub on a laptop have no system users per learner, so this spawner runs every
single-user server as the hub's own account, but still apart:

- its own HOME (``home_dir_template``), so progress, code and bags of one
  learner are never in another's folder;
- its own ``ROS_DOMAIN_ID``: all learners share this machine's loopback, and
  DDS on one loopback separates participants only by domain. The lowest id
  no running server holds is taken and given back when the server stops; a
  hub with more running learners than ids refuses the next spawn with a
  clear message (one network holds ids 0-101, DESIGN.md section 4).

Under a container spawner (KubeSpawner, DockerSpawner) every learner has a
loopback of their own and none of this is needed: domain 0 for all.
"""

from __future__ import annotations

import os
import sys
import threading
from typing import Any, ClassVar

from jupyterhub.spawner import LocalProcessSpawner, SimpleLocalProcessSpawner
from traitlets import Int, Unicode

from app.dds import MAX_DOMAIN_ID


def is_lean(cmd: list[str] | tuple[str, ...]) -> bool:
    """Whether a spawner's command starts the dashboard itself (deploy/jupyterhub_config.py's
    lean mode, ``serve --jupyterhub``) rather than a Jupyter server (the lab mode)."""
    return "--jupyterhub" in cmd and "serve" in cmd


class DomainPool:
    """Which ROS domain ids the running servers of this hub hold."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._held: dict[str, int] = {}

    def take(self, owner: str, first: int, last: int) -> int:
        with self._lock:
            if owner in self._held:
                return self._held[owner]
            used = set(self._held.values())
            for domain in range(first, last + 1):
                if domain not in used:
                    self._held[owner] = domain
                    return domain
        raise RuntimeError(
            f"every ROS domain id {first}..{last} is held by a running learner server: "
            "stop a server, widen the range, or use a container spawner "
            "(each pod has its own loopback)"
        )

    def hold(self, owner: str, domain: int) -> None:
        """An id a running server already has (from the hub's saved state)."""
        with self._lock:
            self._held[owner] = domain

    def give_back(self, owner: str) -> None:
        with self._lock:
            self._held.pop(owner, None)

    def held(self) -> dict[str, int]:
        with self._lock:
            return dict(self._held)


def with_project_commands(env: dict[str, Any], bin_dir: str | None = None) -> dict[str, Any]:
    """The learner's server finds the project's commands first (``ros2``, ``colcon``).

    A lab-mode terminal inherits its server's PATH, which the spawner copies from
    the hub's: a hub started by path (``.venv/bin/jupyterhub``) without its venv on
    PATH would give learners a terminal with no ``ros2``. The hub runs in the
    project's environment, so its interpreter's folder is where those commands are.
    """
    bin_dir = bin_dir or os.path.dirname(sys.executable)
    parts = [p for p in str(env.get("PATH", "")).split(os.pathsep) if p and p != bin_dir]
    return {**env, "PATH": os.pathsep.join([bin_dir, *parts])}


class ClassroomSystemUserSpawner(LocalProcessSpawner):
    """JupyterHub's local spawner (each learner as their own system user), plus a ROS domain id."""

    pool: ClassVar[DomainPool] = DomainPool()
    domain_id: int | None = None

    first_domain_id = Int(1, config=True, help="Lowest ROS domain id given to a learner.")
    last_domain_id = Int(MAX_DOMAIN_ID, config=True, help="Highest ROS domain id given out.")

    def _owner(self) -> str:
        return self.user.name + (f":{self.name}" if self.name else "")

    def get_env(self) -> dict[str, Any]:
        env = with_project_commands(super().get_env())
        self.domain_id = self.pool.take(self._owner(), self.first_domain_id, self.last_domain_id)
        env["ROS_DOMAIN_ID"] = str(self.domain_id)
        return env

    # A hub restarted with cleanup_servers=False finds its servers running: their ids
    # must stay held, or the next learner would get a running learner's domain.
    def get_state(self) -> dict[str, Any]:
        state = super().get_state()
        if self.domain_id is not None:
            state["ros_domain_id"] = self.domain_id
        return state

    def load_state(self, state: dict[str, Any]) -> None:
        super().load_state(state)
        if "ros_domain_id" in state:
            self.domain_id = int(state["ros_domain_id"])
            self.pool.hold(self._owner(), self.domain_id)

    def clear_state(self) -> None:
        super().clear_state()
        self.domain_id = None

    async def stop(self, now: bool = False) -> None:
        try:
            await super().stop(now=now)
        finally:
            self.pool.give_back(self._owner())


class ClassroomLocalSpawner(ClassroomSystemUserSpawner, SimpleLocalProcessSpawner):
    """Single-user servers as the hub's account, each with its own HOME and ROS domain id."""

    home_dir_template = Unicode(
        os.path.join(os.path.expanduser("~"), "ros2-classroom-hub", "{username}"),
        config=True,
        help="Each learner's HOME ({username} is the hub user's name).",
    )

    def get_args(self) -> list[str]:
        args = list(super().get_args())
        # CI machines run as root; jupyter-server refuses that without this (the lean
        # mode's dashboard, `serve --jupyterhub`, takes no Jupyter options).
        if os.geteuid() == 0 and not is_lean(self.cmd):
            args.append("--ServerApp.allow_root=True")
        return args
