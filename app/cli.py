"""``ros2-classroom``: serve the dashboard, run or list catalog nodes.

Errors a user can cause (unknown node, busy port, bad domain id) print one
clear line and exit non-zero; they never show a traceback.
"""

from __future__ import annotations

import argparse
import faulthandler
import logging
import os
import resource
import socket
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from app import catalog
from app.dds import configure_this_process, validate_domain_id
from app.hosts import is_loopback
from app.ros2cli.groups import GROUPS
from app.stop_signals import set_on_signals

if TYPE_CHECKING:
    from app.containment.policy import RunPolicy
    from app.dashboard import Dashboard
    from app.exercises.workspace import Workspace
    from app.hub.singleuser_auth import HubLogin
    from app.teacher.beacon import ProgressBeacon

EXIT_USAGE = 2
EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, as a shell tool killed by it reports


class CliError(Exception):
    """A problem the user can fix; printed as one line."""


def _domain_id(text: str) -> int:
    try:
        return validate_domain_id(int(text))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _port(text: str) -> int:
    try:
        port = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a port number: {text!r}") from None
    if not 1 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"port must be 1-65535, got {port}")
    return port


def _check_port_free(host: str, port: int) -> None:
    # viser silently moves to the next port when ours is taken; say so instead.
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        # As servers bind (viser's too): a browser's connection to a dashboard that just
        # ended lingers in TIME_WAIT for a minute, and that is no reason to refuse.
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind((host, port))
        except OSError as exc:
            raise CliError(
                f"port {port} on {host} is already in use ({exc.strerror}); "
                f"stop the other program or pick another port with --port"
            ) from None


def _access_token(args: argparse.Namespace) -> str | None:
    """Beyond loopback only with --allow-remote, and then always with a token."""
    from app.access import AccessError, check_token, new_token

    if not is_loopback(args.host) and not args.allow_remote:
        raise CliError(
            f"refusing to serve on {args.host}: the dashboard can start processes, so it "
            "only listens on this machine (127.0.0.1) unless you add --allow-remote "
            "(which also requires an access token)"
        )
    if not (args.allow_remote or args.token):
        return None
    try:
        return check_token(args.token) if args.token else new_token()
    except AccessError as exc:
        raise CliError(str(exc)) from None


def _run_policy(args: argparse.Namespace, progress_dir: Path, workspace: Workspace) -> RunPolicy:
    """Learner code: as the user on loopback; served to others, only contained and allowed."""
    from app.containment.policy import RunPolicy

    if is_loopback(args.host):
        return RunPolicy()
    own = workspace.scratch.resolve()

    def holds_own(path: Path) -> bool:
        return own == path.resolve() or own.is_relative_to(path.resolve())

    # Our progress, the other learners' (siblings in a classroom) and their scratch folders.
    candidates = [progress_dir, *progress_dir.parent.glob("*"), *workspace.scratch_root.glob("*")]
    hidden = tuple(p for p in candidates if p.is_dir() and not holds_own(p))
    return RunPolicy(allowed=args.allow_learner_code, contained=True, hidden=hidden)


def cmd_serve(args: argparse.Namespace) -> int:
    hub_login = _hub_singleuser(args)  # `serve --jupyterhub`: the hub's login, not a token
    token = None if hub_login is not None else _access_token(args)
    configure_this_process(domain_id=args.domain_id, network=args.network)
    _check_port_free(args.host, args.port)

    from app.bags import folder as bag_folder
    from app.lessons.progress import DEFAULT_DIR, ProgressStore

    # Tracebacks behind the one-line errors of the page go to this process's log.
    logging.basicConfig(
        level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s"
    )
    progress = ProgressStore(args.learner, args.progress_dir or DEFAULT_DIR)
    # Bags typed in the browser stay in this learner's bags folder (beside progress).
    os.environ.setdefault(
        bag_folder.ENV_VAR, str((args.progress_dir or DEFAULT_DIR).parent / "bags" / args.learner)
    )
    bag_folder.confine_to_folder()
    stop_requested = threading.Event()
    set_on_signals(stop_requested)

    # The web server first, with only what it needs (viser, no rclpy): a browser opened at
    # the address said next loads viser's client while the rest is imported and built,
    # and is sent the dashboard as it is built (app/ui/opening.py).
    from app.access import make_server
    from app.exercises.editor_server import EditorHub
    from app.ui.base_path import BasePathPage
    from app.ui.opening import Opening
    from app.ui.page_links import PageLinks

    editor_hub = EditorHub()
    # Extra routes on viser's server: links, then the page's base-path shim, then the editor.
    page_links = PageLinks(BasePathPage(editor_hub))
    server, _gate = make_server(args.host, args.port, token, page_links, gate=hub_login)
    if server.get_port() != args.port:
        server.stop()
        raise CliError(f"port {args.port} on {args.host} became busy; pick another with --port")
    opening = Opening(server)
    query = f"/?token={token}" if token else _hub_path(hub_login)
    address = f"http://{args.host}:{args.port}{query}"
    print(f"ROS 2 Classroom is starting: {address}  (the page fills in as it starts)", flush=True)

    # The heavy imports, only for the command that needs them.
    from app.dashboard import Dashboard
    from app.exercises.panel import ExerciseSettings
    from app.exercises.workspace import Workspace
    from app.ros.liveness import ParticipantLiveness
    from app.ros.runtime import RosRuntime
    from app.supervisor import Supervisor

    runtime = RosRuntime()
    # A hung DDS participant freezes the whole process; a guard outside it notices, and
    # faulthandler writes every thread's stack to the log when the guard ends us.
    faulthandler.enable()
    # ...and no core file: dumping a few hundred MB would outlast the guard's 3 s to SIGKILL.
    resource.setrlimit(resource.RLIMIT_CORE, (0, resource.getrlimit(resource.RLIMIT_CORE)[1]))
    liveness = ParticipantLiveness(runtime.node)
    liveness.start()
    # The learner's colcon workspace and the ament underlay, before the supervisor copies
    # the environment (issue 22: app/ros2cli/pkg.py). Served to other machines, builds
    # are learner code: the workspace lives in the learner's scratch folder, the one
    # place their contained code may write, hidden from every other learner's.
    from app.ros2cli.pkg import setup_workspace

    scratch_root = args.scratch_dir or (args.progress_dir or DEFAULT_DIR).parent / "scratch"
    # Behind the hub's login (serve --jupyterhub) only the learner reaches the dashboard.
    remote = hub_login is None and not is_loopback(args.host)
    if remote:
        from app.containment.contain import SANDBOX_GID

        setup_workspace(
            progress.path, remote=True, home=scratch_root / progress.path.stem, group=SANDBOX_GID
        )
    else:
        setup_workspace(progress.path, remote=False)
    supervisor = Supervisor(os.environ)
    workspace = Workspace(progress, scratch_root)
    policy = (
        _hub_run_policy()
        if hub_login is not None
        else _run_policy(args, progress.path.parent, workspace)
    )
    settings = ExerciseSettings(policy, args.reveal_solution_after)
    supervisor.learner_policy = settings.policy  # `ros2 launch` of a learner's launch file
    dashboard = Dashboard(
        server, runtime, supervisor, progress, editor_hub, workspace, settings, page_links
    )
    dashboard.start()
    opening.done()
    beacon = _progress_beacon(args, dashboard)
    domain = os.environ.get("ROS_DOMAIN_ID", "0")
    scope = "network (opt-in)" if args.network else "loopback only"
    if remote:
        print(_containment_line(args.allow_learner_code), flush=True)
    print(
        f"ROS 2 Classroom is ready: {address}  "
        f"(ROS domain {domain}, DDS {scope}). Press Ctrl+C to stop.",
        flush=True,
    )
    stop_requested.wait()
    print("Shutting down…", flush=True)
    started = time.monotonic()
    steps = _ShutdownSteps()
    if beacon is not None:
        steps.run("progress beacon", beacon.close)
    if hub_login is not None:
        steps.run("hub login", hub_login.close)
    steps.run("dashboard", dashboard.stop)
    steps.run("editor", editor_hub.close)  # its tasks end on viser's loop, before it stops
    steps.run("ROS guard", liveness.stop)
    steps.run("ROS layer", runtime.shutdown)
    steps.run("nodes", lambda: supervisor.shutdown(timeout=2.5))
    steps.run("web server", server.stop)
    print(f"Stopped in {time.monotonic() - started:.1f} s{steps.slow()}.", flush=True)
    # All this process owns has stopped; Python's exit is left (joining worker threads,
    # freeing ROS objects). Should that stall, every thread's stack goes to the log
    # first: a rehearsal's dashboard said "Stopped in 2.9 s" and was there 5 s later.
    faulthandler.dump_traceback_later(EXIT_STALL_SEC)
    return 0


EXIT_STALL_SEC = 3.0  # from "Stopped in" to the end of the process; usually well under 1 s
SLOW_STEP_SEC = 0.5  # a shutdown step this long is named in the "Stopped in" line


class _ShutdownSteps:
    """Each step of the shutdown timed, so the last line names the slow ones."""

    def __init__(self) -> None:
        self._took: list[tuple[str, float]] = []

    def run(self, name: str, step: Callable[[], object]) -> None:
        began = time.monotonic()
        step()
        self._took.append((name, time.monotonic() - began))

    def slow(self) -> str:
        slow = [f"{name} {sec:.1f} s" for name, sec in self._took if sec >= SLOW_STEP_SEC]
        return f" ({', '.join(slow)})" if slow else ""


def _containment_line(allowed: bool) -> str:
    """What happens to learner code on a dashboard served to others, said at start."""
    from app.containment.sandbox import sandbox_available

    missing = sandbox_available()
    if missing is None:
        if allowed:
            return (
                "Learner code: runs contained (a uid of its own per program, Landlock file "
                "rules, seccomp, ROS 2 over loopback only, CPU/memory/process limits)."
            )
        return "Learner code: off (add --allow-learner-code to run it contained)."
    if allowed:
        return (
            "Learner code: REFUSED despite --allow-learner-code: this environment cannot "
            f"contain it ({missing}). Lessons, catalog nodes and the Console work; running, "
            "building and completing learner code are refused, never run uncontained."
        )
    return f"Learner code: off; containment is not available here either ({missing})."


def _hub_singleuser(args: argparse.Namespace) -> HubLogin | None:
    """``serve --jupyterhub``: this dashboard is a learner's JupyterHub server (the lean mode).

    The hub's spawner says where to listen, under which base path and for
    whom; the hub's OAuth admits the learner (app/hub/singleuser_auth.py).
    Progress, code and bags go to ``~/ros2-classroom/`` as in the Jupyter mode,
    so a learner keeps them when the operator switches modes. None without
    the flag.
    """
    if not args.jupyterhub:
        return None
    from app.hub.server_proxy import learner_home
    from app.hub.singleuser_auth import HubLogin, HubSettings, HubSettingsError

    if args.token or args.allow_remote:
        raise CliError("--jupyterhub logs learners in through the hub: drop --token/--allow-remote")
    try:
        settings = HubSettings.from_env()
    except HubSettingsError as exc:
        raise CliError(str(exc)) from None
    args.host = settings.host or "0.0.0.0"  # a spawner's '' means every interface
    args.port = settings.port
    if args.progress_dir is None:
        args.progress_dir = learner_home() / "progress"
    return HubLogin(settings)


def _hub_run_policy() -> RunPolicy:
    """Behind the hub's login only the learner (or an admin the hub lets in) reaches the
    dashboard, which runs as the learner, in their own container under a container
    spawner: their code runs as in their own terminal, as in the Jupyter mode."""
    from app.containment.policy import LOOPBACK_POLICY

    return LOOPBACK_POLICY


def _hub_path(hub_login: HubLogin | None) -> str:
    return hub_login.settings.prefix if hub_login is not None else ""


def _progress_beacon(args: argparse.Namespace, dashboard: Dashboard) -> ProgressBeacon | None:
    """In a classroom: report this learner's progress to the teacher (app/teacher/beacon.py)."""
    from app.teacher.hub_link import HubTarget

    hub = HubTarget.from_env()  # inside a JupyterHub server: HTTP to the teacher service
    if args.classroom_domain_id is None and hub is None:
        return None
    from app.lessons.schema import load_course
    from app.teacher.beacon import LearnerSources, ProgressBeacon

    sources = LearnerSources(
        load_course(),
        dashboard.lessons,
        dashboard.exercises,
        dashboard.workspace,
        dashboard.supervisor,
        dashboard.exercise_settings,
    )
    beacon = ProgressBeacon(
        dashboard.ui,
        sources,
        dashboard.notice,
        site="hub" if hub else args.site,
        learner=hub.learner if hub else args.learner,
        domain_id=int(os.environ.get("ROS_DOMAIN_ID", "0")),
        classroom_domain=None if hub else args.classroom_domain_id,
        hub=hub,
    )
    beacon.start()
    return beacon


def cmd_classroom_status(args: argparse.Namespace) -> int:
    """The teacher page's table in a terminal (app/teacher/status.py)."""
    from app.lessons.progress import DEFAULT_DIR
    from app.teacher.status import StatusError, status

    try:
        print(status(args.progress_dir or DEFAULT_DIR / "classroom"))
    except StatusError as exc:
        raise CliError(str(exc)) from None
    return 0


def cmd_classroom(args: argparse.Namespace) -> int:
    """N isolated learner dashboards (app/classroom.py); URLs printed, Ctrl+C stops all."""
    from app import classroom
    from app.access import AccessError, check_token, new_token
    from app.lessons.progress import DEFAULT_DIR

    if args.verb == "status":
        return cmd_classroom_status(args)
    if args.learners is None:
        raise CliError("say how many learners: `ros2-classroom classroom --learners N`")
    if not is_loopback(args.host) and not args.allow_remote:
        raise CliError(
            f"refusing to serve on {args.host}: add --allow-remote (each learner then gets "
            "an access token in their URL)"
        )
    progress_root = args.progress_dir or DEFAULT_DIR / "classroom"
    learners = classroom.plan(
        args.learners,
        base_port=args.base_port,
        base_domain=args.base_domain_id,
        progress_root=progress_root,
        tokens=args.allow_remote,
        site=args.site,
        classroom_domain=args.classroom_domain_id,
    )
    teacher_port = args.teacher_port or (
        args.base_port - 1 if args.base_port > 1 else args.base_port + args.learners
    )
    if teacher_port in [learner.port for learner in learners]:
        raise CliError(f"--teacher-port {teacher_port} is also a learner's port")
    try:
        teacher_token = check_token(args.teacher_token) if args.teacher_token else new_token()
    except AccessError as exc:
        raise CliError(f"--teacher-token: {exc}") from None
    if any(teacher_token == learner.token for learner in learners):
        raise CliError("the teacher's token must differ from every learner's")
    teacher = classroom.TeacherPlan(
        teacher_port,
        teacher_token,
        args.classroom_domain_id,
        progress_root,
        args.reveal_solution_after,
    )
    for learner in learners:
        _check_port_free(args.host, learner.port)
    _check_port_free(args.host, teacher_port)
    chosen = (
        ("--allow-remote", args.allow_remote),
        ("--network", args.network),
        ("--allow-learner-code", args.allow_learner_code),
    )
    flags = tuple(flag for flag, on in chosen if on)
    if args.reveal_solution_after is not None:
        flags += ("--reveal-solution-after", str(args.reveal_solution_after))
    stop_requested = threading.Event()
    set_on_signals(stop_requested)
    room = classroom.Classroom(
        learners,
        os.environ,
        host=args.host,
        serve_flags=flags,
        warm=False if args.cold_start else None,  # None: warm unless CLASSROOM_COLD_START=1
    )
    configure_this_process(network=args.network)  # the teacher page's DDS participant
    return classroom.run(room, stop_requested, lambda line: print(line, flush=True), teacher)


def _run_entry(args: argparse.Namespace) -> catalog.CatalogEntry:
    """``run NAME`` (a catalog name) or, as the tutorials type it, ``run PACKAGE EXECUTABLE``."""
    extra = args.ros_args
    from app.ros2cli.run import EXECUTABLES  # a catalog name may also be a package's (issue 23)

    if (
        extra
        and not extra[0].startswith("-")
        and (args.node not in catalog.names() or (args.node, extra[0]) in EXECUTABLES)
    ):
        from app.ros.errors import Ros2Error
        from app.ros2cli.run import resolve

        try:
            return resolve(args.node, extra.pop(0))
        except Ros2Error as exc:
            raise CliError(str(exc)) from None
    return catalog.lookup(args.node)


def cmd_run(args: argparse.Namespace) -> int:
    from app.ros.errors import Ros2Error
    from app.ros2cli.pkg import terminal_argv

    try:  # a package of a sourced colcon workspace, as ros2run finds it (issue 22)
        own = terminal_argv(args.node, list(args.ros_args))
    except Ros2Error as exc:
        raise CliError(str(exc)) from None
    if own is not None:
        configure_this_process(domain_id=args.domain_id, network=args.network)
        os.execv(own[0], own)
    entry = _run_entry(args)
    configure_this_process(domain_id=args.domain_id, network=args.network)
    argv = [sys.executable, "-m", f"nodes.{entry.module}", *entry.argv_tail()]
    extra = list(args.ros_args)
    from app.ros2cli.tool_args import FREE_FORM  # tf2 tools take words (issue 23)

    if entry.module in FREE_FORM and extra and extra[0] != "--ros-args":
        words = extra[: extra.index("--ros-args")] if "--ros-args" in extra else extra
        argv += words
        extra = extra[len(words) :]
    if entry.module == "robot_state_publisher" and extra and extra[0].endswith(".urdf"):
        argv.append(extra.pop(0))  # upstream's URDF-file argument
    if extra:
        if extra[0] != "--ros-args":
            raise CliError("extra arguments must follow --ros-args, as with `ros2 run`")
        argv += extra[1:] if entry.ros_args else extra
    # Replace this process, as `ros2 run` does: Ctrl+C goes straight to the node.
    os.execv(sys.executable, argv)
    return 0  # not reached


def cmd_list(args: argparse.Namespace) -> int:
    width = max(len(name) for name in catalog.names())
    print("Catalog nodes (ros2-classroom run <name>):")
    for entry in catalog.ENTRIES:
        print(f"  {entry.name:<{width}}  {entry.summary}")
    print("\nLaunch groups:")
    for group in catalog.GROUPS:
        print(f"  {group.name:<{width}}  {group.summary}")
    return 0


def cmd_launch(args: argparse.Namespace) -> int:
    """Run a launch group in the foreground (app/launch.py), or print its launch file."""
    from app.launch import launch_file_text, launch_in_foreground

    if args.words or args.group.endswith(".py") or os.path.isfile(args.group):
        return _ros2_launch([args.group, *args.words], args)  # `ros2 launch PKG FILE [args]`
    if args.print_launch_file:
        print(launch_file_text(args.group), end="")
        return 0
    catalog.lookup_group(args.group)
    configure_this_process(domain_id=args.domain_id, network=args.network)
    return launch_in_foreground(args.group, os.environ)


def _ros2_launch(words: list[str], args: argparse.Namespace) -> int:
    """Replace this process with ros2launch (app/launch_prefix.py), as `ros2 launch` runs."""
    from app.launch_prefix import ROS2LAUNCH_MAIN, with_catalog_prefix

    if args.print_launch_file:
        raise CliError("--print takes a launch group name (see `ros2-classroom list`)")
    configure_this_process(domain_id=args.domain_id, network=args.network)
    argv = [sys.executable, str(ROS2LAUNCH_MAIN), *(["-s"] if args.show_args else []), *words]
    os.execve(sys.executable, argv, with_catalog_prefix(os.environ))
    return 0  # not reached


def cmd_exercise(args: argparse.Namespace) -> int:
    """Exercises from a terminal (app/exercises/cli.py)."""
    from app.exercises.cli import main as exercise_main

    if args.verb == "check":
        configure_this_process(domain_id=args.domain_id, network=args.network)
    return exercise_main(args.verb, args.slug, args.file, seed=args.seed)


def cmd_lti(args: argparse.Namespace) -> int:
    """What to paste into an LMS to add the tool (app/lti/lms_setup.py); makes the key once."""
    from app.lti.dynamic_registration import registration_url
    from app.lti.keys import DEFAULT_DIR, ToolKeys
    from app.lti.lms_setup import setup_text
    from app.lti.routes import ToolUrls

    urls = ToolUrls.from_base(args.base_url)
    keys = ToolKeys.load_or_create(args.keys_dir or DEFAULT_DIR)
    folder = args.lti_dir or Path(os.environ.get("CLASSROOM_LTI_DIR") or DEFAULT_DIR.parent)
    print(setup_text(urls, keys, registration_url(urls, folder)))
    return 0


def cmd_foxglove(args: argparse.Namespace) -> int:
    """The live ROS graph for Foxglove or Lichtblick (app/foxglove), until Ctrl+C."""
    if not is_loopback(args.host) and not args.allow_remote:
        raise CliError(
            f"refusing to serve on {args.host}: a Foxglove client may publish on ROS (drive "
            "the robot) and needs no password, so the bridge listens on this machine "
            "(127.0.0.1) unless you add --allow-remote"
        )
    configure_this_process(domain_id=args.domain_id, network=args.network)
    _check_port_free(args.host, args.port)
    from app.foxglove.serve import serve

    stop_requested = threading.Event()
    set_on_signals(stop_requested)
    try:
        return serve(args.host, args.port, stop_requested, lambda line: print(line, flush=True))
    except RuntimeError as exc:  # foxglove-sdk's FoxgloveError: the port went meanwhile
        raise CliError(f"cannot serve on {args.host}:{args.port}: {exc}") from None


ROS2_GROUPS = GROUPS  # the Console's groups, as the command line's verbs


def cmd_ros2(args: argparse.Namespace) -> int:
    """One ros2-like verb (see app/ros2cli), in a fresh short-lived ROS participant."""
    configure_this_process(domain_id=args.domain_id, network=args.network)
    from app.ros2cli.cli import main as ros2_main

    return ros2_main([*filter(None, [args.group]), *args.words], prog=args.prog)


def build_parser(prog: str = "ros2-classroom") -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog, description="A browser-based teaching dashboard for ROS 2 Jazzy."
    )
    parser.set_defaults(prog=prog)
    sub = parser.add_subparsers(dest="command", required=True)

    def dds_options(p: argparse.ArgumentParser) -> None:
        p.add_argument(
            "--domain-id",
            type=_domain_id,
            default=None,
            help="ROS_DOMAIN_ID to use (default: $ROS_DOMAIN_ID or 0)",
        )
        p.add_argument(
            "--network",
            action="store_true",
            help="let DDS use the network cards to reach other machines (default: loopback only)",
        )

    serve = sub.add_parser("serve", help="start the dashboard web server")
    serve.add_argument("--host", default="127.0.0.1", help="address to listen on")
    serve.add_argument("--port", type=_port, default=8080, help="port to listen on")
    serve.add_argument(
        "--allow-remote",
        action="store_true",
        help="allow a --host other than loopback; every browser then needs the access token",
    )
    serve.add_argument(
        "--token",
        default=os.environ.get("CLASSROOM_TOKEN"),
        help="access token (default: $CLASSROOM_TOKEN, else a random one printed with the URL)",
    )
    serve.add_argument("--learner", default="default", help="whose lesson progress to keep")
    serve.add_argument(
        "--jupyterhub",
        action="store_true",
        help="be a learner's JupyterHub single-user server: address, base path and login "
        "from the hub's spawner (deploy/jupyterhub_config.py, lean mode)",
    )
    serve.add_argument(
        "--allow-learner-code",
        action="store_true",
        help="with --allow-remote: let learners run their exercise code (always contained)",
    )
    serve.add_argument(
        "--reveal-solution-after",
        type=int,
        default=None,
        metavar="N",
        help="failed checks before an exercise's reference solution may be shown",
    )
    serve.add_argument(
        "--scratch-dir",
        type=Path,
        default=None,
        help="where learner code runs (default: scratch/ beside the progress folder)",
    )
    serve.add_argument(
        "--progress-dir",
        type=Path,
        default=None,
        help="where progress is saved (default var/progress)",
    )
    serve.add_argument(
        "--classroom-domain-id",
        type=_domain_id,
        default=None,
        help="in a classroom: report progress to the teacher page on this shared ROS domain",
    )
    serve.add_argument(
        "--site", default=socket.gethostname(), help="in a classroom: this machine's name"
    )
    dds_options(serve)
    serve.set_defaults(func=cmd_serve)

    room = sub.add_parser(
        "classroom", help="start N isolated learner dashboards and the teacher page"
    )
    room.add_argument(
        "verb",
        nargs="?",
        choices=("start", "status"),
        default="start",
        help="status: print the running classroom's table (default: start one)",
    )
    room.add_argument("--learners", type=int, default=None, help="how many learners")
    room.add_argument("--base-port", type=_port, default=8080, help="first learner's port")
    room.add_argument(
        "--base-domain-id", type=_domain_id, default=10, help="first learner's ROS domain id"
    )
    room.add_argument("--host", default="127.0.0.1", help="address to listen on")
    room.add_argument(
        "--allow-remote", action="store_true", help="serve other machines (tokens per learner)"
    )
    room.add_argument(
        "--progress-dir", type=Path, default=None, help="parent of each learner's progress"
    )
    room.add_argument("--network", action="store_true", help="let DDS use the network cards")
    room.add_argument(
        "--allow-learner-code",
        action="store_true",
        help="with --allow-remote: learners may run their exercise code (always contained)",
    )
    room.add_argument(
        "--cold-start",
        action="store_true",
        help="start every dashboard by itself, not as a fork of one warm parent "
        "(as CLASSROOM_COLD_START=1; slower, for comparing or debugging)",
    )
    room.add_argument(
        "--reveal-solution-after",
        type=int,
        default=None,
        metavar="N",
        help="failed checks before an exercise's reference solution may be shown",
    )
    room.add_argument(
        "--teacher-port",
        type=_port,
        default=None,
        help="the teacher page's port (default: one below --base-port)",
    )
    room.add_argument(
        "--teacher-token",
        default=os.environ.get("CLASSROOM_TEACHER_TOKEN"),
        help="the teacher page's token (default: $CLASSROOM_TEACHER_TOKEN, else a random one)",
    )
    room.add_argument(
        "--classroom-domain-id",
        type=_domain_id,
        default=101,
        help="ROS domain shared by every learner and the teacher page, for progress only "
        "(default 101; the same on every host of one class)",
    )
    room.add_argument(
        "--site",
        default=socket.gethostname(),
        help="this host's name on the teacher page (default: the hostname)",
    )
    room.set_defaults(func=cmd_classroom)

    run = sub.add_parser("run", help="run one catalog node in the foreground, like `ros2 run`")
    run.add_argument("node", help="catalog name (see `ros2-classroom list`), or PACKAGE EXECUTABLE")
    run.add_argument("ros_args", nargs=argparse.REMAINDER, help="--ros-args ...")
    dds_options(run)
    run.set_defaults(func=cmd_run)

    lst = sub.add_parser("list", help="print the node catalog")
    lst.set_defaults(func=cmd_list)

    launch = sub.add_parser("launch", help="start a launch group, like `ros2 launch`")
    launch.add_argument(
        "group", help="launch group name (see `ros2-classroom list`), or PACKAGE, or a FILE"
    )
    launch.add_argument(
        "words", nargs="*", help="PACKAGE FILE [name:=value ...] or FILE [name:=value ...]"
    )
    launch.add_argument(
        "-s", "--show-args", action="store_true", help="show a launch file's arguments"
    )
    launch.add_argument(
        "--print", dest="print_launch_file", action="store_true", help="print its launch file"
    )
    dds_options(launch)
    launch.set_defaults(func=cmd_launch)

    exercise = sub.add_parser("exercise", help="list, print or grade the exercises")
    exercise.add_argument("verb", choices=("list", "starter", "solution", "check", "explain"))
    exercise.add_argument("slug", nargs="?", help="the exercise (see `exercise list`)")
    exercise.add_argument("file", nargs="?", type=Path, help="check: the file to grade")
    exercise.add_argument("--seed", type=int, help="check: replay a grading's random inputs")
    dds_options(exercise)
    exercise.set_defaults(func=cmd_exercise)

    lti = sub.add_parser("lti", help="LTI 1.3: the values to paste into Moodle, Canvas, Open edX")
    lti.add_argument("verb", choices=("config",))
    lti.add_argument("--base-url", required=True, help="where the LMS reaches this tool")
    lti.add_argument(
        "--keys-dir", type=Path, default=None, help="the tool key's folder (default var/lti/keys)"
    )
    lti.add_argument(
        "--lti-dir",
        type=Path,
        default=None,
        help="the LTI service's folder, for the registration URL's key "
        "(default $CLASSROOM_LTI_DIR, else var/lti)",
    )
    lti.set_defaults(func=cmd_lti)

    fox = sub.add_parser(
        "foxglove", help="serve the live ROS graph to Foxglove or Lichtblick (WebSocket)"
    )
    fox.add_argument("--host", default="127.0.0.1", help="address to listen on")
    fox.add_argument("--port", type=_port, default=8765, help="port to listen on (default 8765)")
    fox.add_argument(
        "--allow-remote", action="store_true", help="allow a --host other than loopback"
    )
    dds_options(fox)
    fox.set_defaults(func=cmd_foxglove)

    # ros2-like verbs (app/ros2cli): `ros2-classroom topic list -t` is `ros2 topic list -t`.
    for group in ROS2_GROUPS:
        verb = sub.add_parser(group, help=f"like `ros2 {group} ...`", add_help=False)
        dds_options(verb)
        verb.add_argument("words", nargs=argparse.REMAINDER, help="verb and its arguments")
        verb.set_defaults(func=cmd_ros2, group=group)
    return parser


def main(argv: list[str] | None = None, prog: str = "ros2-classroom") -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = build_parser(prog)
    if argv[:1] and argv[0] in ROS2_GROUPS:
        # Options before the verb (`topic -h`, `topic --include-hidden-topics type X`) are the
        # verb's, as in `ros2`: hand them on instead of rejecting them here.
        args, before = parser.parse_known_args(argv)
        args.words = [*before, *args.words]
    else:
        args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (CliError, catalog.UnknownNodeError, ValueError) as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return EXIT_USAGE


def ros2(argv: list[str] | None = None) -> int:
    """The ``ros2`` command of a terminal (issue 37): ``ros2 topic list`` is
    ``ros2-classroom topic list``, ``ros2 run``/``ros2 launch`` are its ``run``/``launch``.

    Anything else (``ros2``, ``ros2 --help``, a command we lack) goes to the
    Console's parser, which lists the groups and says what is wrong. DDS stays
    on loopback as for every command of ours (``ros2 GROUP --network ...`` opts in).
    """
    argv = sys.argv[1:] if argv is None else argv
    # The venv is this machine's ROS install: it stays under a sourced workspace, as
    # /opt/ros/jazzy does (that workspace's setup.bash set AMENT_PREFIX_PATH without it).
    prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    if sys.prefix not in prefixes:
        os.environ["AMENT_PREFIX_PATH"] = os.pathsep.join([*prefixes, sys.prefix])
    try:
        if argv[:1] and argv[0] in (*ROS2_GROUPS, "run", "launch"):
            return main(argv, prog="ros2")
        return cmd_ros2(
            argparse.Namespace(domain_id=None, network=False, group=None, words=argv, prog="ros2")
        )
    except BrokenPipeError:
        # `ros2 interface list | head`: the reader has all it wants; no traceback, as a
        # shell tool ends. stdout goes nowhere so the interpreter's last flush stays quiet.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
