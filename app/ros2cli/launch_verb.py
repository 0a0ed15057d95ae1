"""`ros2 launch PKG FILE`: the tutorials' launch files, started through the supervisor.

``launch`` and ``launch_ros`` are not on PyPI, and a console must not run a
Python file a page sent it. So a launch file is a *name* here: ``LAUNCH_FILES``
maps ``(package, file)`` onto a catalog launch group, whose members are the
nodes that file describes. ``turtlesim multisim.launch.py`` is upstream's
file (turtlesim twice, in the namespaces /turtlesim1 and /turtlesim2); every
catalog group is also ``tutorial_nodes <group>.launch.py``, the file
``app.launch.launch_file_text`` writes for it.

As with ``ros2 run``, the Console has one command line, so the nodes keep
running in the background: the verb prints what ``ros2 launch`` prints while
they start (each process labelled ``executable-N``) and returns.
``ros2 launch --stop PKG FILE`` (ours, not ros2's) stops them again, as Ctrl+C
would; the Nodes tab and ``ros2 run --stop NODE`` stop single members.
"""

from __future__ import annotations

import argparse
from typing import Any

from app.catalog import GROUPS, CatalogEntry, LaunchGroup, lookup, lookup_group
from app.ros.context import CallContext
from app.ros.errors import Ros2Error
from app.ros2cli.run import STARTUP_WAIT_SEC, Programs, programs_of, running_as

# (package, launch file) -> catalog launch group.
LAUNCH_FILES: dict[tuple[str, str], str] = {
    ("turtlesim", "multisim.launch.py"): "multisim",
    **{("tutorial_nodes", f"{group.name}.launch.py"): group.name for group in GROUPS},
}


def resolve(package: str, launch_file: str) -> LaunchGroup:
    """The launch group that ``package``'s ``launch_file`` describes."""
    name = LAUNCH_FILES.get((package, launch_file))
    if name is not None:
        return lookup_group(name)
    known = sorted(f for pkg, f in LAUNCH_FILES if pkg == package)
    if known:
        raise Ros2Error(
            f"file '{launch_file}' was not found in the share directory of package "
            f"'{package}' here (it has: {', '.join(known)})"
        )
    packages = sorted({pkg for pkg, _file in LAUNCH_FILES})
    raise Ros2Error(f"Package '{package}' not found (known here: {', '.join(packages)})")


def _labels(members: list[CatalogEntry]) -> dict[str, str]:
    """ros2 launch names each process after its executable, numbered in start order."""
    return {entry.name: f"{entry.module}-{i}" for i, entry in enumerate(members, start=1)}


def _programs(ctx: CallContext, group: LaunchGroup) -> Programs:
    if ctx.programs is None:
        raise Ros2Error(
            "`ros2 launch` starts nodes through the dashboard's supervisor, which this console "
            f"was not given; in a terminal use `ros2-classroom launch {group.name}`"
        )
    return programs_of(ctx)


def launch(ctx: CallContext, package: str, launch_file: str, arguments: list[str]) -> int:
    group = resolve(package, launch_file)
    programs = _programs(ctx, group)
    if arguments:
        raise Ros2Error(f"{launch_file} takes no launch arguments here, got {arguments}")
    members = [lookup(name) for name in group.members]
    running = {running_as(programs, key) for key in programs.statuses()} - {None}
    clashes = [entry.node_name for entry in members if entry.node_name in running]
    if clashes:
        raise Ros2Error(
            f"{', '.join(clashes)} already running; stop it first "
            f"(`ros2 launch --stop {package} {launch_file}` or `ros2 run --stop NODE`)"
        )
    labels = _labels(members)
    ctx.write("[INFO] [launch]: Default logging verbosity is set to INFO")
    for entry in members:
        status = programs.start_program(entry)
        ctx.write(f"[INFO] [{labels[entry.name]}]: process started with pid [{status.pid}]")
    _show_start(ctx, programs, members, labels)
    ctx.write(
        f"({len(members)} nodes keep running: stop them with "
        f"`ros2 launch --stop {package} {launch_file}`, or one by one in the Nodes tab)"
    )
    return 0


def _show_start(
    ctx: CallContext, programs: Programs, members: list[CatalogEntry], labels: dict[str, str]
) -> None:
    """Each member's start-up lines, prefixed with its label, until all are on the graph."""
    shown = dict.fromkeys(labels, 0)
    waited = 0.0
    limit = min(STARTUP_WAIT_SEC, ctx.limits.max_seconds or STARTUP_WAIT_SEC)
    while True:
        for entry in members:
            lines = programs.output(entry.name)
            for line in lines[shown[entry.name] :]:
                ctx.write(f"[{labels[entry.name]}] {line}")
            shown[entry.name] = len(lines)
        on_graph = {
            f"{ns.rstrip('/')}/{name}" for name, ns in ctx.node.get_node_names_and_namespaces()
        }
        ready = all(
            (entry.node_name in on_graph and shown[entry.name])
            or not programs.status(entry.name).active
            for entry in members
        )
        if ready or waited >= limit:
            break
        ctx.sleep(0.1)
        waited += 0.1
    for entry in members:
        status = programs.status(entry.name)
        if not status.active:
            ctx.write(f"[ERROR] [{labels[entry.name]}]: {status.describe()}")


def stop(ctx: CallContext, package: str, launch_file: str) -> int:
    """What Ctrl+C does to a ``ros2 launch`` terminal: stop every member, wait for each."""
    group = resolve(package, launch_file)
    programs = _programs(ctx, group)
    members = [lookup(name) for name in group.members]
    labels = _labels(members)
    started = programs.statuses()
    active = [e for e in members if e.name in started and started[e.name].active]
    if not active:
        raise Ros2Error(f"{launch_file} is not running here")
    ctx.write("[WARNING] [launch]: user interrupted with ctrl-c (SIGINT)")
    futures = [(entry, programs.stop(entry.name)) for entry in active]
    for entry, future in futures:
        status = future.result(timeout=10.0)
        ctx.write(f"[INFO] [{labels[entry.name]}]: {status.describe()}")
    return 0


def add_command(groups: Any, write: Any) -> None:
    """Register `launch` on the parser's sub-command table (parser.build_parser)."""
    p = groups.add_parser(
        "launch", help="start a launch file's nodes: ros2 launch PACKAGE FILE", write=write
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
