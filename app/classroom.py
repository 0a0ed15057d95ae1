"""Classroom mode: one command, N isolated learner dashboards.

Each learner gets a whole ``ros2-classroom serve`` process of their own: own
port, own ROS domain id (so nobody's nodes show up in anybody else's graph),
own learner name and progress directory. Isolation comes from DDS domains
and separate processes, not from new machinery. The children die with this
process (parent-death signal) and are stopped in parallel on Ctrl+C.

The teacher sees every learner on one page (``app.teacher``), served by this
command on its own port with its own token. Each dashboard reports its
progress on the *classroom domain*, a ROS domain that all learners and the
teacher share (a second, small participant per dashboard; the learners' own
domains stay isolated). With ``--network`` that domain reaches other
machines, so a class spread over several hosts (each running ``classroom``
with its own ``--site`` and base domain id) shows on any host's teacher page.

Warm start (app/warm_start.py): the imports every dashboard needs are paid
once, by a warm parent that starts nothing; each learner's dashboard is a
fork of it that then starts as a cold ``serve`` does, and is this command's
child all the same. ``CLASSROOM_COLD_START=1`` starts every dashboard cold;
a warm parent that cannot start, or a fork that fails, means a cold start
for those learners, said on the console.

With ``CLASSROOM_LTI_URL`` set (the address an LMS reaches this classroom
at), the classroom is also an LTI 1.3 tool: the hub's LTI handlers on a port
of their own (app/hub/lti_classroom.py), an LMS learner seated at a learner
dashboard of their own, grades sent from the teacher page's roster, and the
teacher's gradebook behind the teacher's token.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import urlsplit

from app import PROJECT_ROOT
from app.dds import MAX_DOMAIN_ID
from app.restart_rule import GuardMark, ended_for_a_restart
from app.stop_signals import die_with
from app.warm_start import COLD_START_VAR, WarmChild, WarmStarter, WarmStartError, cold_start_asked

if TYPE_CHECKING:
    from app.hub.lti_classroom import ClassroomLtiServer
    from app.teacher.page import TeacherPage
    from app.teacher.record import LearnerRecord
    from app.teacher.roster import Roster

READY_TIMEOUT_SEC = 90.0
# A learner's dashboard ended by its ROS guard or a native crash (app/restart_rule.py)
# starts again, at most this often in one session: one that keeps dying is only reported.
MAX_RESTARTS = 3
MAX_LEARNERS = 40
LTI_URL_ENV = "CLASSROOM_LTI_URL"  # as the hub's teacher service reads it
LTI_PORT_ENV = "CLASSROOM_LTI_PORT"  # where the LTI server listens (default: teacher page - 1)
LTI_DIR_ENV = "CLASSROOM_LTI_DIR"  # the tool's key, platforms.toml, launches, seats and outbox


@dataclass(frozen=True)
class Learner:
    name: str
    port: int
    domain_id: int
    progress_dir: Path
    token: str | None = None
    site: str = "local"
    classroom_domain: int | None = None  # where progress goes (None: nowhere)

    def url(self, host: str) -> str:
        # 0.0.0.0 is every address: show the name other machines can use.
        shown = socket.gethostname() if host == "0.0.0.0" else host
        query = f"/?token={self.token}" if self.token else ""
        return f"http://{shown}:{self.port}{query}"


def plan(
    learners: int,
    *,
    base_port: int,
    base_domain: int,
    progress_root: Path,
    tokens: bool = False,
    site: str = "local",
    classroom_domain: int | None = None,
) -> list[Learner]:
    """Who gets which port, domain and directory; raises ValueError on an impossible plan."""
    from app.access import new_token

    if not 1 <= learners <= MAX_LEARNERS:
        raise ValueError(f"--learners must be 1-{MAX_LEARNERS}, got {learners}")
    if base_port + learners - 1 > 65535:
        raise ValueError(f"ports {base_port}..{base_port + learners - 1} do not all exist")
    if not 0 <= base_domain or base_domain + learners - 1 > MAX_DOMAIN_ID:
        raise ValueError(
            f"domain ids {base_domain}..{base_domain + learners - 1} must lie in 0..{MAX_DOMAIN_ID}"
        )
    if classroom_domain is not None and base_domain <= classroom_domain < base_domain + learners:
        raise ValueError(
            f"the classroom domain {classroom_domain} is also a learner's domain "
            f"({base_domain}..{base_domain + learners - 1}); pick another --classroom-domain-id"
        )
    return [
        Learner(
            name=f"learner{i + 1}",
            port=base_port + i,
            domain_id=base_domain + i,
            progress_dir=progress_root / f"learner{i + 1}",
            token=new_token() if tokens else None,
            site=site,
            classroom_domain=classroom_domain,
        )
        for i in range(learners)
    ]


@dataclass(frozen=True)
class TeacherPlan:
    """The teacher page: its port and token, and the domain it listens on."""

    port: int
    token: str
    classroom_domain: int
    progress_root: Path  # where `classroom status` finds the page
    reveal_after: int | None = None

    def url(self, host: str) -> str:
        # By name, so the learners' 127.0.0.1 URLs stay the only ones of that form.
        shown = {"0.0.0.0": socket.gethostname(), "127.0.0.1": "localhost"}.get(host, host)
        return f"http://{shown}:{self.port}/?token={self.token}"


class TeacherView:
    """The teacher page and the roster behind it, in this process."""

    def __init__(self, plan: TeacherPlan, host: str, site: str = "local") -> None:
        from app.teacher.page import LocalAttempts, TeacherPage
        from app.teacher.roster import Roster
        from app.teacher.status import write_teacher_file

        self.plan = plan
        self.roster: Roster = Roster(plan.classroom_domain)
        self.page: TeacherPage | None = None
        try:
            self.page = TeacherPage(
                host,
                plan.port,
                plan.token,
                self.roster,
                reveal_after=plan.reveal_after,
                # Every dashboard here keeps its attempts beside its progress (app/cli.py).
                attempts=LocalAttempts(plan.progress_root / "bags", site),
            )
            if self.page.port != plan.port:
                raise ValueError(f"port {plan.port} became busy; pick another with --teacher-port")
        except BaseException:
            self.close()
            raise
        self.page.start()
        local = "127.0.0.1" if host == "0.0.0.0" else host
        write_teacher_file(plan.progress_root, f"http://{local}:{plan.port}/", plan.token)

    def close(self) -> None:
        from app.teacher.status import remove_teacher_file

        if self.page is not None:
            self.page.close()
            remove_teacher_file(self.plan.progress_root)
        self.roster.close()


def start_lti(
    classroom: Classroom,
    teacher: TeacherPlan,
    records: Callable[[], list[LearnerRecord]],
    env: Mapping[str, str],
) -> ClassroomLtiServer | None:
    """The LMS's way in, when ``CLASSROOM_LTI_URL`` says where the LMS reaches us; else None.

    Raises ``ValueError``, ``OSError`` or ``RuntimeError`` with the reason (a plain http
    address for another machine, a busy port, no tornado installed).
    """
    base = env.get(LTI_URL_ENV, "").strip()
    if not base:
        return None
    try:
        from app.hub.lti_classroom import DEFAULT_DIR, classroom_lti
    except ImportError as exc:  # tornado comes with the hub extra
        raise RuntimeError(
            f"LTI needs tornado and PyJWT: pip install -e '.[hub]' ({exc})"
        ) from None
    port = int(env.get(LTI_PORT_ENV) or teacher.port - 1)
    if port in [learner.port for learner in classroom.learners] + [teacher.port]:
        raise ValueError(f"the LTI port {port} is also a dashboard's: set {LTI_PORT_ENV}")
    server = classroom_lti(
        base,
        learner_urls={learner.name: learner.url(classroom.host) for learner in classroom.learners},
        teacher_url=teacher.url(classroom.host),
        teacher_token=teacher.token,
        site=classroom.learners[0].site,
        host=classroom.host,
        port=port,
        records=records,
        folder=Path(env.get(LTI_DIR_ENV) or DEFAULT_DIR),
        progress_root=teacher.progress_root,  # each seat's attempts: <root>/bags/<seat>/
    )
    server.start()
    return server


def _lti_lines(lti: ClassroomLtiServer, host: str) -> list[str]:
    from app.hosts import is_loopback

    lines = [
        f"  LMS (LTI 1.3): {lti.lti.tool.urls.base}  (served on {host}:{lti.port}; "
        f"`ros2-classroom lti config --base-url {lti.lti.tool.urls.base}` prints what the "
        "LMS needs)",
        f"  Gradebook: {lti.gradebook_url}",
    ]
    public = urlsplit(lti.lti.tool.urls.base).hostname or ""
    if is_loopback(host) and not is_loopback(public):
        lines.append(
            "  Note: the dashboards listen on this machine only: learners from the LMS on "
            "other machines need --host 0.0.0.0 --allow-remote"
        )
    return lines


Process = subprocess.Popen[bytes] | WarmChild  # a dashboard started cold, or a warm fork


class Classroom:
    """The learner dashboards as child processes; start, watch, stop."""

    def __init__(
        self,
        learners: list[Learner],
        env: Mapping[str, str],
        *,
        host: str = "127.0.0.1",
        serve_flags: tuple[str, ...] = (),
        log_dir: Path | None = None,
        warm: bool | None = None,
        say: Callable[[str], None] | None = None,
    ) -> None:
        self.learners = learners
        self.host = host
        self._env = dict(env)
        self._flags = serve_flags
        self._log_dir = log_dir
        # Warm start unless told otherwise (warm=False, or CLASSROOM_COLD_START=1).
        self.warm = not cold_start_asked(env) if warm is None else warm
        self.say: Callable[[str], None] = say or (lambda line: print(line, flush=True))
        self.warm_starter: WarmStarter | None = None
        self._procs: dict[str, Process] = {}
        self._ready: dict[str, threading.Event] = {}
        self._marks_dir: Path | None = None  # each dashboard's guard mark, while it runs
        self._marks: dict[str, GuardMark] = {}

    def start(self) -> None:
        self._marks_dir = Path(tempfile.mkdtemp(prefix="classroom-guard-marks-"))
        self.warm_starter = self._start_warm_parent() if self.warm else None
        if not self.warm:
            self.say(f"Cold start ({COLD_START_VAR}=1): each dashboard imports everything itself.")
        for learner in self.learners:
            self.start_learner(learner)

    def start_learner(self, learner: Learner) -> None:
        """``learner``'s dashboard, warm if it can be, with its log pump and ready flag."""
        argv = [
            sys.executable, "-m", "app", "serve",
            "--host", self.host,
            "--port", str(learner.port),
            "--domain-id", str(learner.domain_id),
            "--learner", learner.name,
            "--progress-dir", str(learner.progress_dir),
            *self._flags,
        ]  # fmt: skip
        if learner.classroom_domain is not None:
            argv += [
                "--classroom-domain-id", str(learner.classroom_domain), "--site", learner.site
            ]  # fmt: skip
        env = {**self._env, "PYTHONUNBUFFERED": "1"}
        if self._marks_dir is not None:
            mark = self._marks[learner.name] = GuardMark(self._marks_dir, learner.name)
            env.update(mark.env())
        env.pop("CLASSROOM_TOKEN", None)
        if learner.token:  # through the environment: a token on argv shows in `ps`
            env["CLASSROOM_TOKEN"] = learner.token
        proc = self._start_warm(learner, argv, env) or subprocess.Popen(
            argv,
            cwd=PROJECT_ROOT,
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # Ctrl+C reaches us; we stop them in order
            preexec_fn=die_with(os.getpid()),
        )
        self._procs[learner.name] = proc
        self._ready[learner.name] = threading.Event()
        threading.Thread(
            target=self._pump, args=(learner, proc), name=f"log-{learner.name}", daemon=True
        ).start()

    def _start_warm_parent(self) -> WarmStarter | None:
        """The warm parent, ready; None (said why) when it cannot start: everyone starts cold."""
        log = self._log_dir / "warm-parent.log" if self._log_dir is not None else None
        if self._log_dir is not None:
            self._log_dir.mkdir(parents=True, exist_ok=True)
        starter = WarmStarter(self._env, say=self.say, log_path=log)
        try:
            starter.start()
        except WarmStartError as exc:
            self.say(f"Warm start unavailable ({exc}): every dashboard starts cold.")
            return None
        self.say(
            f"Warm start: the dashboards fork from one warm parent (pid {starter.pid}) that "
            f"imported everything once, in {starter.import_sec:.1f} s "
            f"({COLD_START_VAR}=1 starts each cold)."
        )
        return starter

    def _start_warm(self, learner: Learner, argv: list[str], env: dict[str, str]) -> Process | None:
        """The learner's dashboard as a fork of the warm parent; None: start it cold."""
        if self.warm_starter is None:
            return None
        try:
            return self.warm_starter.spawn(argv, env, PROJECT_ROOT)
        except WarmStartError as exc:
            self.say(f"  {learner.name}: warm start failed ({exc}); starting it cold.")
            return None

    def watch(self) -> None:
        """Call now and then: a warm parent that ended is restarted (and said so)."""
        if self.warm_starter is not None:
            self.warm_starter.check()

    def _pump(self, learner: Learner, proc: Process) -> None:
        """Copy a child's output to its log file and notice when it is ready."""
        assert proc.stdout is not None
        log = None
        if self._log_dir is not None:
            self._log_dir.mkdir(parents=True, exist_ok=True)
            log = open(self._log_dir / f"{learner.name}.log", "ab")
        try:
            for raw in proc.stdout:
                if log is not None:
                    log.write(raw)
                    log.flush()
                if b"is ready" in raw:
                    self._ready[learner.name].set()
        finally:
            if log is not None:
                log.close()

    def wait_ready(self, timeout: float = READY_TIMEOUT_SEC) -> list[str]:
        """Names of learners whose dashboard failed to come up in time (empty: all ready)."""
        deadline = time.monotonic() + timeout
        failed = []
        for learner in self.learners:
            while not self._ready[learner.name].wait(0.2):
                if self._procs[learner.name].poll() is not None or time.monotonic() > deadline:
                    failed.append(learner.name)
                    break
        return failed

    def ended(self) -> dict[str, int]:
        """Learner dashboards that have exited, with their exit codes."""
        codes = {name: p.poll() for name, p in self._procs.items()}
        return {name: code for name, code in codes.items() if code is not None}

    def restart_reason(self, name: str, code: int) -> str | None:
        """Why ``name``'s dashboard, ended with ``code``, starts again; None: it stays ended."""
        mark = self._marks.get(name)
        if mark is None:
            return None
        return ended_for_a_restart(code, mark)

    def pids(self) -> dict[str, int]:
        return {name: proc.pid for name, proc in self._procs.items()}

    def stop(self, timeout: float = 10.0) -> None:
        """SIGTERM to all at once (each stops its own nodes), SIGKILL what remains."""
        for proc in self._procs.values():
            if proc.poll() is None:
                proc.send_signal(signal.SIGTERM)
        deadline = time.monotonic() + timeout
        for proc in self._procs.values():
            try:
                proc.wait(max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
        if self.warm_starter is not None:
            self.warm_starter.close()
        if self._marks_dir is not None:
            shutil.rmtree(self._marks_dir, ignore_errors=True)


def run(
    classroom: Classroom,
    stop_requested: threading.Event,
    say: Callable[[str], None] = print,
    teacher: TeacherPlan | None = None,
) -> int:
    """Start everyone and the teacher page, print the URLs, stop on request."""
    classroom.say = say
    classroom.start()
    view = lti = None
    if teacher is not None:  # while the dashboards boot
        try:
            view = TeacherView(teacher, classroom.host, classroom.learners[0].site)
        except (OSError, ValueError, RuntimeError) as exc:
            say(f"ros2-classroom: error: could not start the teacher page: {exc}")
            classroom.stop()
            return 1
        try:
            lti = start_lti(classroom, teacher, view.roster.records, os.environ)
        except (OSError, ValueError, RuntimeError) as exc:
            say(f"ros2-classroom: error: could not serve LTI for the LMS: {exc}")
            view.close()
            classroom.stop()
            return 1
    try:
        extra = _lti_lines(lti, classroom.host) if lti is not None else []
        return _serve(classroom, stop_requested, say, teacher, extra)
    finally:
        if lti is not None:
            lti.close()
        if view is not None:
            view.close()


def _serve(
    classroom: Classroom,
    stop_requested: threading.Event,
    say: Callable[[str], None],
    teacher: TeacherPlan | None,
    extra: list[str] | None = None,
) -> int:
    failed = classroom.wait_ready()
    if failed:
        say(f"ros2-classroom: error: could not start the dashboard of {', '.join(failed)}")
        classroom.stop()
        return 1
    width = max(len(learner.name) for learner in classroom.learners)
    say(f"Classroom is ready: {len(classroom.learners)} learners, each isolated.")
    for learner in classroom.learners:
        say(
            f"  {learner.name:<{width}}  {learner.url(classroom.host)}  "
            f"(ROS domain {learner.domain_id}, progress in {learner.progress_dir})"
        )
    if teacher is not None:
        say(
            f"  Teacher page: {teacher.url(classroom.host)}  (own token; progress on ROS "
            f"domain {teacher.classroom_domain}; `ros2-classroom classroom status` prints it)"
        )
    for line in extra or []:
        say(line)
    say("Press Ctrl+C to stop every dashboard.")
    reported: set[str] = set()
    restarts: dict[str, int] = {}
    learners = {learner.name: learner for learner in classroom.learners}
    while not stop_requested.wait(0.5):
        classroom.watch()
        for name, code in classroom.ended().items():
            why = classroom.restart_reason(name, code)
            if why is not None and restarts.get(name, 0) < MAX_RESTARTS:
                # Its page comes back by itself, progress kept.
                restarts[name] = restarts.get(name, 0) + 1
                say(f"  {name}'s dashboard ended ({why}); starting it again")
                classroom.start_learner(learners[name])
            elif name not in reported:
                reported.add(name)
                say(f"  {name}'s dashboard ended (exit code {code}); the others keep running")
    say("Stopping the classroom…")
    classroom.stop()
    return 0
