"""`ros2 run PKG EXE [args] [--ros-args ...]`: start a catalog node through the supervisor.

The tutorials name upstream packages (``turtlesim turtlesim_node``,
``demo_nodes_py talker``, ``examples_rclpy_minimal_service service``, ...);
``EXECUTABLES`` maps each onto the catalog entry that plays its part, so the
learner types the tutorial's line and the supervisor, the only owner of node
processes, starts ``python -m nodes.<module>``. Nothing typed reaches a shell:
the ROS arguments are checked one by one (``-r/--remap from:=to``,
``-p/--param name:=value``, ``--params-file FILE``, ``--log-level LEVEL``)
and handed to the node as argv words, where rcl applies them, so a remap such
as ``__node:=my_turtle`` or ``turtle1/cmd_vel:=turtle2/cmd_vel`` is real.

A terminal's ``ros2 run`` holds the terminal until Ctrl+C; the Console has one
command line, so here the node keeps running in the background: the verb
shows what it printed while starting (or, for a short-lived client, all of
it and its exit code) and returns. The Nodes tab stops catalog names;
``ros2 run --stop NODE`` (ours, not ros2cli's) stops any node this verb
started. A second instance needs a different node name (``__node:=``/``__ns:=``);
the same name twice is refused instead of giving the graph two nodes of one
name.

The verb needs the dashboard's supervisor: ``ctx.programs`` (see
``programs_of``). The ``ros2-classroom run`` command runs nodes in a terminal
on its own; it can use ``resolve`` for the ``PKG EXE`` form.
"""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import Future
from dataclasses import replace
from pathlib import Path
from typing import Protocol, cast

import yaml

from app.catalog import ENTRIES, CatalogEntry, UnknownNodeError, lookup
from app.containment.policy import RunPolicy
from app.ros.context import CallContext, Write
from app.ros.errors import Ros2Error
from app.ros2cli import tool_args
from app.ros2cli.common import Commands
from app.supervisor import NodeStatus, Program

# (package, executable) of the tutorials -> catalog name.
UPSTREAM: dict[tuple[str, str], str] = {
    ("turtlesim", "turtlesim_node"): "turtlesim_node",
    ("turtlesim", "turtle_teleop_key"): "turtle_teleop_key",
    ("turtlesim", "mimic"): "turtle_mimic",
    ("demo_nodes_py", "talker"): "talker",
    ("demo_nodes_py", "listener"): "listener",
    ("demo_nodes_cpp", "talker"): "talker",
    ("demo_nodes_cpp", "listener"): "listener",
    ("demo_nodes_py", "add_two_ints_server"): "add_two_ints_server",
    ("demo_nodes_py", "add_two_ints_client"): "add_two_ints_client",
    ("demo_nodes_cpp", "add_two_ints_server"): "add_two_ints_server",
    ("demo_nodes_cpp", "add_two_ints_client"): "add_two_ints_client",
    ("examples_rclpy_minimal_publisher", "publisher_member_function"): "talker",
    ("examples_rclpy_minimal_subscriber", "subscriber_member_function"): "listener",
    ("examples_rclpy_minimal_service", "service"): "add_two_ints_server",
    ("examples_rclpy_minimal_client", "client"): "add_two_ints_client",
    ("py_pubsub", "talker"): "talker",
    ("py_pubsub", "listener"): "listener",
    ("cpp_pubsub", "talker"): "talker",
    ("cpp_pubsub", "listener"): "listener",
    ("py_srvcli", "service"): "add_two_ints_server",
    ("py_srvcli", "client"): "add_two_ints_client",
    ("cpp_srvcli", "server"): "add_two_ints_server",
    ("cpp_srvcli", "client"): "add_two_ints_client",
    ("action_tutorials_py", "fibonacci_action_server"): "fibonacci_action_server",
    ("action_tutorials_py", "fibonacci_action_client"): "fibonacci_action_client",
    ("action_tutorials_cpp", "fibonacci_action_server"): "fibonacci_action_server",
    ("action_tutorials_cpp", "fibonacci_action_client"): "fibonacci_action_client",
    ("lifecycle", "lifecycle_talker"): "lifecycle_talker",
    ("lifecycle_py", "lifecycle_talker"): "lifecycle_talker",
    ("sim_world", "sim_world"): "sim_world",  # issue 26: the MuJoCo world
    # issue 23: tf2's programs and the tf2 tutorials' nodes (turtle_tf2_py; learning_tf2_py
    # is the package the tutorials have the learner write)
    ("tf2_ros", "tf2_echo"): "tf2_echo",
    ("tf2_ros", "tf2_monitor"): "tf2_monitor",
    ("tf2_ros", "static_transform_publisher"): "static_transform_publisher",
    ("tf2_tools", "view_frames"): "view_frames",
    **{
        (pkg, exe): exe
        for pkg in ("turtle_tf2_py", "learning_tf2_py")
        for exe in (
            "static_turtle_tf2_broadcaster",
            "turtle_tf2_broadcaster",
            "turtle_tf2_listener",
            "fixed_frame_tf2_broadcaster",
            "dynamic_frame_tf2_broadcaster",
        )
    },
    ("robot_state_publisher", "robot_state_publisher"): "robot_state_publisher",  # issue 23
    ("joint_state_publisher", "joint_state_publisher"): "joint_state_publisher",
    ("joint_state_publisher_gui", "joint_state_publisher_gui"): "joint_state_publisher_gui",
    ("urdf_tutorial_r2d2", "state_publisher"): "r2d2_state_publisher",
}
# ...and every catalog entry under its own package (`ros2 run tutorial_nodes talker`).
EXECUTABLES: dict[tuple[str, str], str] = {
    **{(entry.package, entry.name): entry.name for entry in ENTRIES},
    **UPSTREAM,
}

STARTUP_WAIT_SEC = 5.0  # how long the verb shows a node that keeps talking, or stays silent
STARTUP_QUIET_SEC = 1.0  # ...and it stops sooner once the node is up and this long quiet
# The longest it waits for a node that has neither spoken nor joined the graph: on a
# loaded computer a Python node can take many seconds just to import rclpy (CI of
# 2026-12-03: turtlesim had not greeted after 5 s, and the Console showed no greeting).
SLOW_START_LIMIT_SEC = 30.0
POLL_SEC = 0.1
_NAME = r"[~/]?[A-Za-z_{][\w/{}~]*"  # a ROS name as a remap rule may write it
_REMAP = re.compile(rf"^(?:(?P<node>[A-Za-z_]\w*):)?(?P<from>{_NAME}|__node|__ns)"
                    rf":=(?P<to>{_NAME})$")  # fmt: skip
_PARAM = re.compile(r"^(?:[A-Za-z_]\w*:)?[A-Za-z_][\w.]*:=[^\n\x00]*$")
_LEVELS = ("debug", "info", "warn", "error", "fatal")
_LOG_LEVEL = re.compile(rf"^(?:[A-Za-z_][\w.]*:=)?(?:{'|'.join(_LEVELS)})$", re.IGNORECASE)


class Programs(Protocol):
    """What the verb needs of the supervisor (app.supervisor.Supervisor has it)."""

    learner_policy: RunPolicy | None  # how learner code may run here (None: it may not)

    def start_program(self, entry: Program, extra_ros_args: Iterable[str] = ()) -> NodeStatus: ...

    def status(self, name: str) -> NodeStatus: ...

    def statuses(self) -> Mapping[str, NodeStatus]: ...

    def output(self, name: str, last: int | None = None) -> list[str]: ...

    def stop(self, name: str) -> Future[NodeStatus]: ...


def programs_of(ctx: CallContext) -> Programs:
    """The supervisor the console was given (``CallContext.programs``), or an error."""
    programs = ctx.programs
    if programs is None:
        raise Ros2Error(
            "`ros2 run` starts nodes through the dashboard's supervisor, which this console "
            "was not given; in a terminal use `ros2-classroom run NODE` with a catalog name"
        )
    return cast(Programs, programs)


def resolve(package: str, executable: str) -> CatalogEntry:
    """The catalog entry that plays ``package``'s ``executable``."""
    name = EXECUTABLES.get((package, executable))
    if name is not None:
        return lookup(name)
    known = sorted(exe for pkg, exe in EXECUTABLES if pkg == package)
    if known:
        raise Ros2Error(
            f"No executable found: '{executable}' is not in package '{package}' here "
            f"(it has: {', '.join(known)})"
        )
    packages = sorted({pkg for pkg, _exe in EXECUTABLES})
    raise Ros2Error(f"Package '{package}' not found (known here: {', '.join(packages)})")


def executables(package: str | None = None) -> list[tuple[str, str]]:
    """(package, executable) pairs as `ros2 pkg executables` lists them.

    An upstream package lists the tutorial names it maps (turtlesim: mimic,
    turtle_teleop_key, turtlesim_node), not the catalog's variants of them.
    """
    upstream = {pkg for pkg, _exe in UPSTREAM}
    pairs = [
        (pkg, exe) for pkg, exe in EXECUTABLES if (pkg, exe) in UPSTREAM or pkg not in upstream
    ]
    if package is not None:
        pairs = [(pkg, exe) for pkg, exe in pairs if pkg == package]
        if not pairs:
            raise Ros2Error(f"Package '{package}' not found")
    return sorted(pairs)


def split_ros_args(words: list[str]) -> tuple[list[str], list[str]]:
    """Program arguments, then the checked ROS arguments after ``--ros-args``."""
    if "--ros-args" not in words:
        return list(words), []
    at = words.index("--ros-args")
    program, rest = words[:at], words[at + 1 :]
    if rest and rest[-1] == "--":
        rest = rest[:-1]
    return program, check_ros_args(rest)


def check_ros_args(words: list[str]) -> list[str]:
    """Only the ROS arguments the tutorials use, each well formed; returns argv words."""
    checked: list[str] = []
    it = iter(words)
    for flag in it:
        value = next(it, None)
        if flag in ("-r", "--remap", "-p", "--param", "--params-file", "--log-level"):
            if value is None:
                raise Ros2Error(f"{flag} needs a value after it")
        if flag in ("-r", "--remap"):
            if not _REMAP.match(value or ""):
                raise Ros2Error(f"not a remapping rule: {value!r} (expected from:=to)")
            checked += ["-r", value or ""]
        elif flag in ("-p", "--param"):
            if not _PARAM.match(value or ""):
                raise Ros2Error(f"not a parameter assignment: {value!r} (expected name:=value)")
            checked += ["-p", value or ""]
        elif flag == "--params-file":
            checked += ["--params-file", str(params_file(value or ""))]
        elif flag == "--log-level":
            if not _LOG_LEVEL.match(value or ""):
                raise Ros2Error(f"not a log level: {value!r} (one of {', '.join(_LEVELS)})")
            checked += ["--log-level", value or ""]
        else:
            raise Ros2Error(
                f"unsupported ROS argument {flag!r} here "
                "(use -r/--remap, -p/--param, --params-file or --log-level)"
            )
    return checked


def params_file(text: str) -> Path:
    """An existing YAML parameter file (``/node: ros__parameters: ...``), absolute."""
    path = Path(text).expanduser().resolve()
    if path.suffix not in (".yaml", ".yml") or not path.is_file():
        raise Ros2Error(f"no YAML parameter file at {text!r}")
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        data = None
    if not isinstance(data, dict) or not all(
        isinstance(v, dict) and "ros__parameters" in v for v in data.values()
    ):
        raise Ros2Error(f"{text!r} is not a ROS parameter file (node: ros__parameters: ...)")
    return path


def node_name_after(entry: CatalogEntry, ros_args: list[str]) -> str:
    """The fully qualified name the node will have once the remaps apply."""
    namespace, _, name = entry.node_name.rpartition("/")
    rules = [entry.ros_args[i + 1] for i, w in enumerate(entry.ros_args[:-1]) if w == "-r"]
    rules += [ros_args[i + 1] for i, w in enumerate(ros_args[:-1]) if w == "-r"]
    for rule in rules:
        match = _REMAP.match(rule)
        if match is None or match["node"]:
            continue
        if match["from"] == "__node":
            name = match["to"]
        elif match["from"] == "__ns":
            namespace = "/" + match["to"].strip("/")
    return f"{namespace.rstrip('/')}/{name}"


def program_args(entry: CatalogEntry, words: list[str]) -> tuple[str, ...]:
    """Words before ``--ros-args``: numbers for a client that takes them (``client 2 3``)."""
    if entry.module in tool_args.FREE_FORM:  # the tf2 tools: frame names and flags
        return tool_args.check_words(entry.module, words)
    if not words:
        return entry.args
    urdf_file = len(words) == 1 and words[0].endswith((".urdf", ".urdf.xml"))
    if entry.module == "robot_state_publisher" and urdf_file:
        return (str(Path(words[0]).expanduser()),)  # upstream's URDF-file fallback (cwd: project)
    if len(words) != len(entry.args) or not all(re.fullmatch(r"-?\d+", w) for w in words):
        takes = f"{len(entry.args)} whole numbers" if entry.args else "no arguments"
        raise Ros2Error(f"{entry.name} takes {takes} before --ros-args here, got {words}")
    return tuple(words)


def run(ctx: CallContext, package: str, executable: str, words: list[str]) -> int:
    programs = programs_of(ctx)
    entry = resolve(package, executable)
    before, ros_args = split_ros_args(words)
    fqn = node_name_after(entry, ros_args)
    # The catalog name when the node keeps its name (the Nodes tab then shows it).
    key = entry.name if fqn == entry.node_name else f"{entry.name}:{fqn}"
    if _active(programs, key) or any(
        running_as(programs, other) == fqn for other in programs.statuses()
    ):
        raise Ros2Error(
            f"a node named {fqn} is already running; give this one another name "
            "(--ros-args -r __node:=NEW_NAME), or stop it first"
        )
    instance = replace(entry, name=key, node_name=fqn, args=program_args(entry, before))
    programs.start_program(instance, ros_args)
    return _show_start(ctx, programs, key, fqn)


def stop(ctx: CallContext, fqn: str) -> int:
    programs = programs_of(ctx)
    fqn = fqn if fqn.startswith("/") else f"/{fqn}"
    keys = [key for key in programs.statuses() if running_as(programs, key) == fqn]
    if not keys:
        raise Ros2Error(f"no running node named {fqn} was started here")
    for key in keys:
        status = programs.stop(key).result(timeout=10.0)
        ctx.write(f"{fqn}: {status.describe()}")
    return 0


def _active(programs: Programs, key: str) -> bool:
    try:
        return bool(programs.status(key).active)
    except UnknownNodeError:  # an instance name never started
        return False


def running_as(programs: Programs, key: str) -> str | None:
    """The node name of an active supervisor key: 'entry:/fqn', or a catalog name."""
    if not _active(programs, key):
        return None
    if ":" in key:
        return key.split(":", 1)[1]
    try:
        return lookup(key).node_name
    except UnknownNodeError:
        return None


def write_new_output(ctx: CallContext, programs: Programs, key: str, shown: int) -> int:
    """Write lines not shown yet; ``shown`` counts lines ever produced (the buffer is bounded)."""
    status = programs.status(key)
    lines = programs.output(key)
    total = status.dropped_lines + len(lines)
    new = lines[max(0, len(lines) - (total - shown)) :] if total > shown else []
    for line in new:
        ctx.write(line)
    return total


def follow_start(
    ctx: CallContext, programs: Programs, key: str, is_up: Callable[[], object]
) -> NodeStatus:
    """Write what a starting program says until it is up and has gone quiet; its status.

    Up is ``is_up()`` (its node on the graph). The start-up messages of a node come
    in a burst (turtlesim: its greeting, then the first turtle), so the verb waits for
    STARTUP_QUIET_SEC without a new line. A node that keeps talking is shown for
    STARTUP_WAIT_SEC from its first line, a silent one for as long once it is up; one
    that has done neither yet is waited for up to SLOW_START_LIMIT_SEC (Stop ends the
    wait sooner). A program that ends meanwhile has all its output written.
    """
    shown = 0
    waited = quiet = 0.0
    spoke_at = up_at = None
    while True:
        now_shown = write_new_output(ctx, programs, key, shown)
        quiet = 0.0 if now_shown != shown else quiet
        shown = now_shown
        status = programs.status(key)
        if not status.active:
            write_new_output(ctx, programs, key, shown)
            return status
        if shown and spoke_at is None:
            spoke_at = waited
        if up_at is None and is_up():
            up_at = waited
        if spoke_at is not None:
            done = (up_at is not None and quiet >= STARTUP_QUIET_SEC) or (
                waited - spoke_at >= STARTUP_WAIT_SEC
            )
        else:
            done = up_at is not None and waited - up_at >= STARTUP_WAIT_SEC
        if done or waited >= SLOW_START_LIMIT_SEC:
            return status
        ctx.sleep(POLL_SEC)
        waited += POLL_SEC
        quiet += POLL_SEC


def _show_start(ctx: CallContext, programs: Programs, key: str, fqn: str) -> int:
    """Print what the node says while it starts; all of it if it ends meanwhile."""

    def is_up() -> bool:
        names = ctx.node.get_node_names_and_namespaces()
        return fqn in {f"{ns.rstrip('/')}/{name}" for name, ns in names}

    status = follow_start(ctx, programs, key, is_up)
    if not status.active:
        return 0 if status.exit_code == 0 else 1
    ctx.write(
        f"({fqn} keeps running, pid {status.pid}: stop it with `ros2 run --stop {fqn}`"
        + (" or in the Nodes tab)" if ":" not in key else ")")
    )
    return 0


# `ros2 run` of a package in a sourced workspace (app.ros2cli.pkg.run_own): its exit code,
# or None when the package is not one of those. Given by the parser, so that this module
# (which pkg builds on) does not import pkg back.
OwnFirst = Callable[[CallContext, str, str, list[str]], int | None]


def add_command(groups: Commands, write: Write, own_packages_first: OwnFirst) -> None:
    """Register `run` on the parser's sub-command table (parser.build_parser)."""
    p = groups.add_parser(
        "run", help="start a node: ros2 run PACKAGE EXECUTABLE [--ros-args ...]", write=write
    )
    p.add_argument("--stop", metavar="NODE", help="stop a node started with `ros2 run` (ours)")
    p.add_argument("package", nargs="?")
    p.add_argument("executable", nargs="?")
    p.add_argument("arguments", nargs=argparse.REMAINDER, help="program and --ros-args words")
    p.set_defaults(handler=lambda ctx, args: _handle(ctx, args, own_packages_first))


def pkg_executables(ctx: CallContext, package: str | None) -> int:
    for pkg, exe in executables(package):
        ctx.write(f"{pkg} {exe}")
    return 0


def _handle(ctx: CallContext, args: argparse.Namespace, own_packages_first: OwnFirst) -> int:
    if args.stop:
        return stop(ctx, args.stop)
    if not args.package or not args.executable:
        raise Ros2Error("usage: ros2 run PACKAGE EXECUTABLE [args] [--ros-args ...]")
    # A sourced workspace's packages first (issue 22), as a sourced overlay shadows.
    own = own_packages_first(ctx, args.package, args.executable, list(args.arguments))
    if own is not None:
        return own
    return run(ctx, args.package, args.executable, list(args.arguments))
