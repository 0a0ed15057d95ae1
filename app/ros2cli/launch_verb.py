"""`ros2 launch PKG FILE [name:=value ...]`: a real launch file, run by ros2launch as ONE program.

The file is found as ``ros2 launch`` finds it: in the package's share folder
(searched recursively) through the ament index, whose prefixes are the
learner's sourced workspaces (``AMENT_PREFIX_PATH``) and then the catalog's
own prefix (``app.launch_prefix``: ``turtlesim multisim.launch.py`` and
``tutorial_nodes <group>.launch.py`` for every catalog launch group). The
supervisor starts ``ros2launch`` with it as one program; its nodes are that
program's children, in its process group, so ``--stop`` (Ctrl+C) reaches all
of them and the supervisor reaps them all. A launch file that is not ours is
learner code: it runs as the learner's exercise code runs (refused, or
contained, when the dashboard serves other machines).

The Console has one command line, so the launch keeps running in the
background: the verb shows what ``ros2 launch`` prints while the nodes start
and returns. ``ros2 launch --stop PKG FILE`` (ours, not ros2's) is Ctrl+C.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from app.ros.context import CallContext, Write
from app.ros.errors import Ros2Error
from app.ros2cli.common import Commands
from app.ros2cli.run import Programs, programs_of

_ARGUMENT = re.compile(r"^[A-Za-z_][\w.-]*:=[^\n\x00]*$")
_STARTED = re.compile(r"^\[INFO\] \[(?P<label>[^\]]+)\]: process started with pid \[\d+\]$")
_INTERRUPTED = "[WARNING] [launch]: user interrupted with ctrl-c (SIGINT)"
# How long the verb shows a starting launch: until every process has printed a line,
# or this long after the first one did (a node may stay silent until it hears
# something; counted from that first line, so a slow start does not cut the others off:
# CI of 2026-12-04 showed turtlesim2's greeting after 10 s and lost turtlesim1's)...
STARTUP_WAIT_SEC = 10.0
# ...or this long while none has: several rclpy nodes starting at once on a loaded
# computer can take that long (CI of 2026-12-03: no turtlesim had greeted after 10 s).
SLOW_START_LIMIT_SEC = 30.0
STOP_WAIT_SEC = 20.0  # above the supervisor's SIGINT -> SIGTERM -> SIGKILL escalation


def program_key(package: str, launch_file: str) -> str:
    """The supervisor's name for one launch file's program."""
    return f"launch:{package}/{launch_file}"


def _programs(ctx: CallContext, package: str, launch_file: str) -> Programs:
    if ctx.programs is None:
        raise Ros2Error(
            "`ros2 launch` starts nodes through the dashboard's supervisor, which this console "
            f"was not given; in a terminal use `ros2-classroom launch {package} {launch_file}`"
        )
    return programs_of(ctx)


def _active(programs: Programs, key: str) -> bool:
    status = programs.statuses().get(key)
    return status is not None and bool(status.active)


def _find(package: str, launch_file: str) -> Path:
    from app.launch_prefix import LaunchFileNotFound, find_launch_file

    try:
        return find_launch_file(package, launch_file)
    except LaunchFileNotFound as exc:
        raise Ros2Error(str(exc)) from None


def launch(ctx: CallContext, package: str, launch_file: str, arguments: list[str]) -> int:
    programs = _programs(ctx, package, launch_file)
    path = _find(package, launch_file)
    for argument in arguments:
        if not _ARGUMENT.match(argument):
            raise Ros2Error(
                f"malformed launch argument '{argument}', expected format '<name>:=<value>'"
            )
    key = program_key(package, launch_file)
    if _active(programs, key):
        raise Ros2Error(
            f"{package} {launch_file} is already running here; stop it first "
            f"(`ros2 launch --stop {package} {launch_file}`)"
        )
    from app.launch_prefix import LaunchRefused, is_ours, launch_program

    policy = programs.learner_policy
    try:
        program = launch_program(
            key, "", [str(path), *arguments], path.parent, policy, trusted=is_ours(path)
        )
    except LaunchRefused as exc:
        raise Ros2Error(str(exc)) from None
    programs.start_program(program)
    return _show_start(ctx, programs, key, package, launch_file)


def _show_start(
    ctx: CallContext, programs: Programs, key: str, package: str, launch_file: str
) -> int:
    """What ros2 launch prints while its processes start; all of it if it ends meanwhile."""
    shown = 0
    waited = 0.0
    first_spoke_at: float | None = None  # the wait for the silent ones counts from here
    # Not a stream: the Console's limit for streams does not apply.
    while True:
        lines = programs.output(key)
        for line in lines[shown:]:
            ctx.write(line)
        shown = len(lines)
        status = programs.status(key)
        if not status.active:
            if status.exit_code != 0:
                ctx.write(f"[ERROR] [launch]: ros2 launch {status.describe()}")
            return 0 if status.exit_code == 0 else 1
        labels = [m["label"] for line in lines if (m := _STARTED.match(line))]
        spoke = {label for label in labels if any(x.startswith(f"[{label}] ") for x in lines)}
        if spoke and first_spoke_at is None:
            first_spoke_at = waited
        if labels and len(spoke) == len(labels):
            break
        if first_spoke_at is None:
            if waited >= SLOW_START_LIMIT_SEC:
                break
        elif waited - first_spoke_at >= STARTUP_WAIT_SEC:
            break
        ctx.sleep(0.1)
        waited += 0.1
    ctx.write(
        f"(the launch keeps running: stop it with `ros2 launch --stop {package} {launch_file}`)"
    )
    return 0


def stop(ctx: CallContext, package: str, launch_file: str) -> int:
    """What Ctrl+C does to a ``ros2 launch`` terminal: SIGINT to all, escalated, all reaped."""
    programs = _programs(ctx, package, launch_file)
    key = program_key(package, launch_file)
    if not _active(programs, key):
        raise Ros2Error(f"{launch_file} is not running here")
    status = programs.stop(key).result(timeout=STOP_WAIT_SEC)
    lines = programs.output(key)
    start = max((i for i, line in enumerate(lines) if line == _INTERRUPTED), default=None)
    if start is None:
        ctx.write(_INTERRUPTED)
        start = len(lines)
    for line in lines[start:]:
        ctx.write(line)
    if status.exit_code not in (0, None):
        ctx.write(f"[INFO] [launch]: ros2 launch {status.describe()}")
    return 0


def add_command(groups: Commands, write: Write) -> None:
    """Register `launch` on the parser's sub-command table (parser.build_parser)."""
    p = groups.add_parser(
        "launch", help="run a launch file: ros2 launch PACKAGE FILE [name:=value ...]", write=write
    )
    p.add_argument("--stop", action="store_true", help="stop that launch file's nodes (ours)")
    p.add_argument("package")
    p.add_argument("launch_file")
    p.add_argument("arguments", nargs=argparse.REMAINDER, help="launch arguments (name:=value)")
    p.set_defaults(handler=_handle)


def _handle(ctx: CallContext, args: argparse.Namespace) -> int:
    if args.stop:
        return stop(ctx, args.package, args.launch_file)
    return launch(ctx, args.package, args.launch_file, list(args.arguments))
