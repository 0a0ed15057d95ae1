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

Warm start (issue 43): in the lean mode both spawners start each dashboard as
a fork of one warm parent per hub (app/warm_start.py, as ``classroom`` does),
so a class arriving together pays the imports once. The fork is still the
learner's own process, session, HOME, domain and token, and the hub's child
(its pid, poll and stop as for a cold start). The system-user spawner's fork
becomes the learner's account (uid, gid, groups) before it runs anything of
theirs, as JupyterHub's ``set_user_setuid`` does before a cold server's exec;
that needs a hub run as root, as that spawner does anyway. Unlike a cold
server a fork ends with the hub (its parent-death signal), which is what the
hub's default ``cleanup_servers`` does on a clean stop; the learner's work is
on disk. A warm parent that cannot start, a fork that fails or a command that
is not ``python -m ...`` starts that learner cold, with a log line;
``CLASSROOM_COLD_START=1`` or ``warm_start = False`` turns it off.
"""

from __future__ import annotations

import asyncio
import logging
import os
import subprocess
import sys
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import IO, ClassVar

from jupyterhub.spawner import LocalProcessSpawner, SimpleLocalProcessSpawner
from jupyterhub.utils import random_port
from traitlets import Bool, Instance, Int, Unicode, Union

from app.dds import MAX_DOMAIN_ID
from app.warm_start import (
    STARTUP_VARS,
    Credentials,
    WarmChild,
    WarmStarter,
    WarmStartError,
    cold_start_asked,
)


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


def with_project_commands(env: dict[str, str], bin_dir: str | None = None) -> dict[str, str]:
    """The learner's server finds the project's commands first (``ros2``, ``colcon``).

    A lab-mode terminal inherits its server's PATH, which the spawner copies from
    the hub's: a hub started by path (``.venv/bin/jupyterhub``) without its venv on
    PATH would give learners a terminal with no ``ros2``. The hub runs in the
    project's environment, so its interpreter's folder is where those commands are.
    """
    bin_dir = bin_dir or os.path.dirname(sys.executable)
    parts = [p for p in str(env.get("PATH", "")).split(os.pathsep) if p and p != bin_dir]
    return {**env, "PATH": os.pathsep.join([bin_dir, *parts])}


def _copy_output(stream: IO[bytes]) -> None:
    """A warm fork's output into the hub's log, as a cold server's inherited stderr."""
    with stream:
        while chunk := os.read(stream.fileno(), 65536):
            sys.stderr.buffer.write(chunk)
            sys.stderr.buffer.flush()


class HubWarmStart:
    """The hub's one warm parent: started by the first lean spawn, shared by every learner."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._starter: WarmStarter | None = None
        self._off = ""  # why warm start is off for this hub ('' while it is on)
        # Forks are asked for one at a time (WarmStarter's lock); these threads keep
        # the waits off the hub's event loop and out of its default executor.
        self.executor = ThreadPoolExecutor(max_workers=2, thread_name_prefix="warm-start")

    def spawn(
        self,
        argv: list[str],
        env: dict[str, str],
        cwd: str,
        user: Credentials | None,
        log: logging.Logger,
    ) -> WarmChild:
        """``argv`` as a fork of the warm parent (started here the first time); WarmStartError."""
        with self._lock:
            if self._off:
                raise WarmStartError(self._off)
            if self._starter is None:
                # Only what is read as a process starts (no learner's token or HOME).
                wanted = {k: v for k, v in env.items() if STARTUP_VARS.match(k) or k == "PATH"}
                starter = WarmStarter(wanted, say=log.info)
                try:
                    starter.start()
                except WarmStartError as exc:
                    self._off = f"the warm parent could not start ({exc})"
                    log.warning("Warm start is off for this hub: %s", self._off)
                    raise
                log.info(
                    "Warm start: learners' dashboards fork from one warm parent (pid %s, "
                    "imports in %.1f s)",
                    starter.pid,
                    starter.import_sec,
                )
                self._starter = starter
        return self._starter.spawn(argv, env, cwd, user)


class ClassroomSystemUserSpawner(LocalProcessSpawner):
    """JupyterHub's local spawner (each learner as their own system user), plus a ROS domain id
    and warm start."""

    pool: ClassVar[DomainPool] = DomainPool()
    domain_id: int | None = None
    warm: ClassVar[HubWarmStart] = HubWarmStart()
    # A cold server's Popen, or a warm fork (the same poll, wait, signals and ``with``).
    proc = Union(
        [Instance(subprocess.Popen), Instance(WarmChild)],
        allow_none=True,
        help="The single-user server's process, started cold or as a warm fork.",
    )

    warm_start = Bool(
        True,
        config=True,
        help="Lean-mode dashboards fork from one warm parent that has paid the imports "
        "(app/warm_start.py); False (or CLASSROOM_COLD_START=1): each starts cold.",
    )

    first_domain_id = Int(1, config=True, help="Lowest ROS domain id given to a learner.")
    last_domain_id = Int(MAX_DOMAIN_ID, config=True, help="Highest ROS domain id given out.")

    def _owner(self) -> str:
        return self.user.name + (f":{self.name}" if self.name else "")

    def get_env(self) -> dict[str, str]:
        env = with_project_commands(super().get_env())
        self.domain_id = self.pool.take(self._owner(), self.first_domain_id, self.last_domain_id)
        env["ROS_DOMAIN_ID"] = str(self.domain_id)
        env["PYTHONUNBUFFERED"] = "1"  # as the warm parent's (app/warm_start.STARTUP_VARS)
        return env

    def warm_identity(self) -> tuple[Credentials | None, str]:
        """Who a warm fork becomes and where it starts: the learner's account and home,
        as JupyterHub's ``set_user_setuid`` gives a cold server."""
        import pwd

        user = pwd.getpwnam(self.user.name)
        groups = os.getgrouplist(self.user.name, user.pw_gid)
        return Credentials(user.pw_uid, user.pw_gid, tuple(groups)), user.pw_dir

    async def start(self) -> tuple[str, int]:
        if not self.warm_start or not is_lean(self.cmd) or self.shell_cmd:
            return await super().start()
        if cold_start_asked(os.environ):  # the switch for every server of this hub
            return await super().start()
        if self.port == 0:  # type: ignore[has-type]  # as LocalProcessSpawner.start
            self.port = random_port()
        env = {k: str(v) for k, v in self.get_env().items()}
        argv = [*self.cmd, *self.get_args()]
        loop = asyncio.get_running_loop()
        try:
            user, cwd = self.warm_identity()
            child = await loop.run_in_executor(
                self.warm.executor, self.warm.spawn, argv, env, cwd, user, self.log
            )
        except (WarmStartError, KeyError, OSError) as exc:
            self.log.warning("Warm start of %s failed (%s): starting it cold", self._owner(), exc)
            return await super().start()
        try:
            assert child.stdout is not None
            stream, child.stdout = child.stdout, None
            threading.Thread(
                target=_copy_output, args=(stream,), name=f"output-{child.pid}", daemon=True
            ).start()
            self.proc = child
            self.pid = child.pid
        except BaseException:  # a server the hub will never know of must not run on
            child.kill()
            child.wait()
            raise
        self.log.info("Warm start: %s's dashboard is pid %d", self._owner(), child.pid)
        return (self.ip or "127.0.0.1", self.port)

    # A hub restarted with cleanup_servers=False finds its servers running: their ids
    # must stay held, or the next learner would get a running learner's domain.
    def get_state(self) -> dict[str, int]:
        state = super().get_state()
        if self.domain_id is not None:
            state["ros_domain_id"] = self.domain_id
        return state

    def load_state(self, state: dict[str, int]) -> None:
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

    def warm_identity(self) -> tuple[Credentials | None, str]:
        """The hub's own account; the learner's HOME (made if new) as the working folder."""
        os.makedirs(self.home_dir, 0o755, exist_ok=True)
        return None, self.home_dir
