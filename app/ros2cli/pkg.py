"""The learner's own packages in the Console: ros2 pkg, colcon, source, and their `ros2 run`.

* ``ros2 pkg create`` is ros2pkg's (ros_python/src/ros2pkg). In the Console
  it acts as if typed in ``~/ros2_ws/src`` (where the tutorials type it);
  ``--destination-directory`` stays inside the workspace. In a terminal it
  writes into the working folder, as upstream.
* ``colcon build|test ...`` runs real colcon in the workspace root as a
  supervisor program (app.learner_ws.build), its output streamed here,
  bounded in time and disk.
* ``source install/setup.bash`` puts that install space over the underlay
  for this Console (app.learner_ws.overlay): `ros2 run`, `ros2 pkg ...`,
  `ros2 interface ...` and the programs started from here see it.
* ``ros2 run PKG EXE`` of a package found in a sourced workspace runs
  ``<prefix>/lib/<pkg>/<exe>`` through the supervisor, like upstream's
  ros2run; catalog packages keep going through ``run``.
* ``ros2 pkg list/executables/prefix`` read the ament index of the search
  path: sourced workspaces first, then the wheels and the catalog's prefixes.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import time
from pathlib import Path

from ros2pkg.verb import add_create_arguments, main_create

from app.learner_ws import build, folder, overlay, served
from app.learner_ws.folder import LearnerWorkspace
from app.ros.context import CallContext, Write
from app.ros.errors import Cancelled, Ros2Error
from app.ros2cli import run
from app.ros2cli.common import Commands, Ros2cliMessage, Verb
from app.ros2cli.run import Programs
from app.supervisor import LearnerProgram, own_program_key

NO_DDS = {("pkg", v) for v in ("create", "list", "executables", "prefix")}
FIRST_WORDS_WITHOUT_DDS = ("colcon", "source")
SETUP_FILES = ("setup.bash", "setup.sh", "setup.zsh", "local_setup.bash", "local_setup.sh")
POLL_SEC = 0.1
DISK_CHECK_SEC = 1.0
PROGRESS_SEC = 5.0  # a progress line after this long without output


def no_dds(words: list[str]) -> bool:
    """colcon and source read and write files only."""
    return bool(words) and words[0] in FIRST_WORDS_WITHOUT_DDS


def workspace() -> LearnerWorkspace | None:
    return folder.current()


# -- the dashboard's wiring ------------------------------------------------------------


def setup_workspace(
    progress_file: Path, *, remote: bool, home: Path | None = None, group: int | None = None
) -> LearnerWorkspace:
    """Called once by `ros2-classroom serve` before the supervisor copies the environment.

    The learner's workspace beside their progress (served to other machines:
    ``home/ros2_ws``, in their scratch folder, where their contained code may
    reach it and no other learner's can; ``group`` the sandbox's), and the
    underlay every program and index lookup sees: the catalog's ament
    prefixes, then what AMENT_PREFIX_PATH held (or the wheels' prefix).
    """
    from app.launch_prefix import catalog_prefix
    from app.ros2cli.tutorial_prefix import tutorial_prefix

    root = home / "ros2_ws" if home is not None else folder.default_root(progress_file)
    ws = LearnerWorkspace(root, remote=remote, group=group)
    folder.configure(ws)
    before = [Path(p) for p in os.environ.get(overlay.PREFIX_ENV, "").split(os.pathsep) if p]
    underlay = [*before, Path(sys.prefix), tutorial_prefix(), catalog_prefix()]
    overlay.set_underlay(underlay)
    os.environ[overlay.PREFIX_ENV] = os.pathsep.join(str(p) for p in overlay.search_path())
    return ws


# -- ros2 pkg --------------------------------------------------------------------------


def add_verbs(verbs: Commands, verb: Verb) -> None:
    """The `pkg` group's verbs (parser.build_parser gives the group and its helper)."""
    p = verb(verbs, "create", "Create a new ROS 2 package", _create)
    add_create_arguments(p)
    verb(verbs, "list", "Output a list of available packages", _list)
    p = verb(verbs, "executables", "Output a list of package specific executables", _executables)
    p.add_argument("package_name", nargs="?")
    p.add_argument("--full-path", action="store_true", help="Show full path of each executable")
    p = verb(verbs, "prefix", "Output the prefix path of a package", _prefix)
    p.add_argument("package_name")
    p.add_argument("--share", action="store_true", help="Show share directory for the package")


def add_commands(groups: Commands, write: Write) -> None:
    """`colcon VERB ...` and `source FILE`: commands the tutorials type beside ros2."""
    p = groups.add_parser("colcon", help="build the workspace: colcon build [options]", write=write)
    p.add_argument("words", nargs=argparse.REMAINDER, help="verb and options")
    p.set_defaults(handler=_colcon)
    p = groups.add_parser("source", help="use a workspace: source install/setup.bash", write=write)
    p.add_argument("file")
    p.set_defaults(handler=_source)


def _create(ctx: CallContext, args: argparse.Namespace) -> int:
    ws = workspace()
    base: Path | None = None
    if ws is not None:
        destination = args.destination_directory
        typed = (
            destination
            if os.path.isabs(destination) or destination.startswith("~")
            else (os.path.join("src", destination))
        )
        real = ws.confine(typed)
        real.mkdir(parents=True, exist_ok=True)
        # Shown as typed; resolved where the tutorial types it (~/ros2_ws/src).
        if destination.startswith("~"):
            args.destination_directory = str(real)
        base = ws.src
    problem = main_create(args, ctx.write, base)
    if problem:
        raise Ros2cliMessage(problem)
    return 0


def _own_packages() -> dict[str, Path]:
    """Packages of sourced workspaces (the overlay), with their prefix."""
    mine = set(overlay.overlay())
    if workspace() is None:  # a terminal: whatever its shell sourced that colcon built
        mine = {p for p in overlay.search_path() if (p / "share" / "colcon-core").is_dir()}
    return {name: prefix for name, prefix in overlay.packages().items() if prefix in mine}


def _list(ctx: CallContext, args: argparse.Namespace) -> int:
    names = set(overlay.packages()) | {pkg for pkg, _exe in run.EXECUTABLES}
    for name in sorted(names):
        ctx.write(name)
    return 0


def _executables(ctx: CallContext, args: argparse.Namespace) -> int:
    own = _own_packages()
    package = args.package_name
    if package is not None and package in own:
        pairs = [(package, p) for p in overlay.executables(package, own[package])]
        for pkg, path in pairs:
            ctx.write(str(path) if args.full_path else f"{pkg} {path.name}")
        return 0
    if package is not None and package not in {pkg for pkg, _exe in run.EXECUTABLES}:
        raise Ros2cliMessage(f"Package '{package}' not found" + _not_found_hint(package))
    lines: list[tuple[str, str]] = []
    for pkg, exe in run.executables(package):
        if pkg not in own:
            prefix = overlay.package_prefix(pkg)
            lines.append((pkg, str(prefix / "lib" / pkg / exe) if prefix else exe))
    if package is None:
        for pkg, own_prefix in own.items():
            lines += [(pkg, str(path)) for path in overlay.executables(pkg, own_prefix)]
    for pkg, shown in sorted(lines):
        ctx.write(shown if args.full_path else f"{pkg} {os.path.basename(shown)}")
    return 0


def _prefix(ctx: CallContext, args: argparse.Namespace) -> int:
    prefix = overlay.package_prefix(args.package_name)
    if prefix is None:
        raise Ros2cliMessage("Package not found")
    ctx.write(str(prefix / "share" / args.package_name) if args.share else str(prefix))
    return 0


# -- source ----------------------------------------------------------------------------


def _source(ctx: CallContext, args: argparse.Namespace) -> int:
    ws = workspace()
    if ws is None:
        raise Ros2Error("`source` is for the dashboard's Console; in a terminal, type it in bash")
    path = ws.confine(args.file)
    if path.name not in SETUP_FILES or path.parent.name != "install":
        raise Ros2Error(
            f"{args.file}: the Console sources a workspace's install/setup.bash "
            "(or setup.sh, local_setup.bash) only"
        )
    if not path.is_file():
        ctx.write(f"bash: {args.file}: No such file or directory")
        ctx.write(
            "(nothing is built yet: `colcon build` in the workspace writes install/setup.bash)"
        )
        return 1
    prefixes = overlay.source(path.parent)
    names = sorted(name for p in prefixes for name in _names_in(p))
    ctx.write(
        f"(sourced {ws.shown(path)}: from now on this Console's `ros2 run`, `ros2 launch`, "
        "`ros2 pkg` and `ros2 interface` find this workspace's packages"
        + (f" ({', '.join(names)})" if names else " (it holds no package yet)")
        + " in front of the underlay, the ROS packages installed here. In a terminal, "
        "sourcing sets AMENT_PREFIX_PATH, PYTHONPATH and LD_LIBRARY_PATH the same way; "
        "a package built later needs `source` again.)"
    )
    return 0


def _names_in(prefix: Path) -> list[str]:
    index = prefix / overlay.INDEX
    return [p.name for p in index.iterdir()] if index.is_dir() else []


# -- colcon ----------------------------------------------------------------------------


def _colcon(ctx: CallContext, args: argparse.Namespace) -> int:
    ws = workspace()
    if ws is None:
        raise Ros2Error("in a terminal, run colcon itself (it is installed in the venv)")
    programs = run.programs_of(ctx)
    words = list(args.words)
    # The rule for learner code (app.supervisor's learner_policy): builds run setup.py.
    program = served.colcon_program(ws, words, programs.learner_policy)
    if _active(programs, program.name):
        raise Ros2Error(f"`colcon {words[0]}` is already running in this workspace")
    programs.start_program(program)
    return follow_build(ctx, programs, program.name, ws)


def follow_build(ctx: CallContext, programs: Programs, key: str, ws: LearnerWorkspace) -> int:
    """Stream a build's output until it ends; stop it at the time or disk limit, or on Stop."""
    started = time.monotonic()
    shown = 0
    next_disk_check = started + DISK_CHECK_SEC
    last_news = started
    reason: str | None = None
    try:
        while True:
            before = shown
            shown = run.write_new_output(ctx, programs, key, shown)
            if shown != before:
                last_news = time.monotonic()
            elif time.monotonic() - last_news >= PROGRESS_SEC:
                # colcon is quiet while CMake or setup.py work: say it is alive.
                last_news = time.monotonic()
                ctx.write(f"(building for {last_news - started:.0f} s: {_progress(programs, key)})")
            status = programs.status(key)
            if not status.active:
                shown = run.write_new_output(ctx, programs, key, shown)
                output = programs.output(key)
                _explain_dash_spelling(ctx, output)
                _point_at_errors(ctx, output, ws, status.exit_code)
                return 0 if status.exit_code == 0 else 1
            now = time.monotonic()
            if now - started > ws.limits.seconds:
                reason = (
                    f"the build ran longer than {ws.limits.seconds:g} s, the limit here, and was "
                    "stopped (does a setup.py or CMakeLists.txt loop forever?)"
                )
                break
            if now >= next_disk_check:
                next_disk_check = now + DISK_CHECK_SEC
                used = build.disk_usage(ws.root)
                if used > ws.limits.disk_bytes:
                    reason = (
                        f"build/, install/ and log/ grew past {ws.limits.disk_bytes // 2**20} MiB, "
                        "the disk budget here, and the build was stopped; your src/ is untouched "
                        "(delete build/ and install/ to start again)"
                    )
                    break
            ctx.sleep(POLL_SEC)
    except Cancelled:
        programs.stop(key).result(timeout=15.0)
        run.write_new_output(ctx, programs, key, shown)
        raise
    programs.stop(key).result(timeout=15.0)
    run.write_new_output(ctx, programs, key, shown)
    ctx.write(f"error: {reason}")
    return 1


def _point_at_errors(
    ctx: CallContext, lines: list[str], ws: LearnerWorkspace, code: int | None
) -> None:
    """After colcon's own lines: each error with the file and line it is in."""
    errors = build.error_summary(lines, ws)
    unread = any("package identification" in line and "ERROR" in line for line in lines)
    if code == 0 and not unread:
        return
    if code == 0:  # colcon skipped a package whose setup.py failed to run, and says 0 failed
        ctx.write("(colcon could not read a package's setup.py, so it did not build that package)")
        code = None
    head = f"colcon ended with exit code {code}" if code else "nothing of it was built"
    if errors:
        ctx.write(f"({head}; where it failed:")
        for error in errors[:8]:  # the place on a line of its own: the Console is narrow
            if error.where:
                ctx.write(f"  {error.where}:")
            ctx.write(f"    {error.text}")
        ctx.write(f" the full logs are in {ws.shown(ws.root / 'log')})")
    else:
        ctx.write(f"({head}: the full logs are in {ws.shown(ws.root / 'log')})")


def _progress(programs: Programs, key: str) -> str:
    """How many packages colcon started and finished so far, from its own lines."""
    lines = programs.output(key)
    began = sum(line.startswith("Starting >>> ") for line in lines)
    done = sum(line.startswith(("Finished <<< ", "Failed   <<< ")) for line in lines)
    return f"{done} of {began} started packages done"


def _explain_dash_spelling(ctx: CallContext, lines: list[str]) -> None:
    """setup.cfg with script-dir/install-scripts (older templates, ros2cli #730)."""
    if any("dash-separated 'script-dir'" in line or "dash-separated 'install-scripts'" in line
           for line in lines):  # fmt: skip
        ctx.write(
            "(hint: setup.cfg says script-dir/install-scripts; setuptools still reads the dash "
            "spelling but warns it will stop, and then your executables would not land in "
            "lib/<package>, where `ros2 run` looks: use script_dir and install_scripts)"
        )


def _active(programs: Programs, key: str) -> bool:
    return key in programs.statuses() and programs.statuses()[key].active


# -- ros2 run of the learner's own packages ----------------------------------------------


def run_own(ctx: CallContext, package: str, executable: str, words: list[str]) -> int | None:
    """`ros2 run` of a package in a sourced workspace; None when it is not one of those."""
    own = _own_packages()
    if package not in own:
        if package not in {pkg for pkg, _exe in run.EXECUTABLES}:
            hint = _not_found_hint(package)
            if hint:
                raise Ros2cliMessage(f"Package '{package}' not found{hint}")
        return None
    ws = workspace()
    paths = [p for p in overlay.executables(package, own[package]) if p.name == executable]
    if not paths:
        present = [p.name for p in overlay.executables(package, own[package])]
        raise Ros2cliMessage(
            "No executable found\n"
            f"(package '{package}' has "
            + (f"the executables {', '.join(present)}" if present else "no executables")
            + ": an ament_python executable is a line of console_scripts in setup.py's "
            "entry_points, 'name = package.module:main', installed into lib/<package> when "
            "setup.cfg says script_dir/install_scripts (underscores); fix it, then "
            "`colcon build` and `source install/setup.bash` again)"
        )
    programs = run.programs_of(ctx)
    before, ros_args = run.split_ros_args(words)
    key = own_program_key(package, executable)
    if _active(programs, key):
        raise Ros2Error(
            f"{package} {executable} is already running; stop it with "
            f"`ros2 run --stop /{package}/{executable}`"
        )
    tail = [*before] + (["--ros-args", *ros_args] if ros_args else [])
    cwd = ws.root if ws is not None else Path.cwd()
    program = LearnerProgram(
        name=key, node_name=f"/{package}/{executable}", argv=(str(paths[0]), *tail), cwd=cwd,
        env=overlay.child_env(), names_its_node=False,
    )  # fmt: skip
    if ws is not None:  # served to other machines: contained, or refused
        program = served.node_program(ws, program, programs.learner_policy)
    nodes_before = _node_names(ctx)
    programs.start_program(program)
    return _show_own_start(ctx, programs, key, nodes_before)


def _node_names(ctx: CallContext) -> set[str]:
    return {f"{ns.rstrip('/')}/{n}" for n, ns in ctx.node.get_node_names_and_namespaces()}


def _show_own_start(ctx: CallContext, programs: Programs, key: str, before: set[str]) -> int:
    """Its output while it starts; all of it when it ends meanwhile (a script that prints)."""
    status = run.follow_start(ctx, programs, key, lambda: _node_names(ctx) - before)
    if not status.active:
        if status.exit_code != 0:
            _explain_missing_module(ctx, programs.output(key), key.split("/")[1])
        return 0 if status.exit_code == 0 else 1
    new_nodes = _node_names(ctx) - before
    stop = key.split(":", 1)[1]
    on_graph = f" as {', '.join(sorted(new_nodes))}" if new_nodes else ""
    ctx.write(
        f"(it keeps running{on_graph}, pid {status.pid}: stop it with `ros2 run --stop {stop}`)"
    )
    return 0


_NO_MODULE = re.compile(r"ModuleNotFoundError: No module named '(?P<module>[^']+)'")
_DEPEND = re.compile(r"<(?:depend|exec_depend|build_depend|build_export_depend)>\s*([^<\s]+)\s*<")


def _declared(package_xml: Path) -> set[str]:
    try:
        return set(_DEPEND.findall(package_xml.read_text(encoding="utf-8", errors="replace")))
    except OSError:
        return set()


def _explain_missing_module(ctx: CallContext, lines: list[str], package: str) -> None:
    """After Python's "No module named 'X'": is X a package package.xml should declare?"""
    found = [m for line in lines if (m := _NO_MODULE.search(line))]
    ws = workspace()
    if not found or ws is None:
        return
    missing = found[-1]["module"].split(".")[0]
    folders = build.package_folders(ws)
    manifest = folders[package] / "package.xml" if package in folders else None
    shown = ws.shown(manifest) if manifest is not None else f"{package}'s package.xml"
    declared = missing in _declared(manifest) if manifest is not None else False
    if missing in folders and not declared:
        ctx.write(
            f"(hint: your node imports {missing}, a package of your workspace, but {shown} "
            f"does not declare it. colcon builds a package after the packages it declares, "
            f"and `colcon build --packages-up-to {package}` builds only those; on another "
            f"machine rosdep installs only what is declared. Add <depend>{missing}</depend> "
            f"to {shown}, then `colcon build --packages-up-to {package}` and "
            "`source install/setup.bash`)"
        )
    elif missing in folders:
        ctx.write(
            f"(hint: {missing} is declared and in src/, but not in the install space this "
            f"Console sourced: `colcon build --packages-up-to {package}`, then "
            "`source install/setup.bash`)"
        )
    elif not declared:
        ctx.write(
            f"(hint: {missing} is neither a package of your workspace nor installed here. If "
            f"it is a ROS package, declare it in {shown} (<depend>{missing}</depend>): on a "
            "ROS machine `rosdep install --from-paths src` installs what package.xml "
            "declares, and nothing else)"
        )


def _not_found_hint(package: str) -> str:
    """Why a package of the learner's workspace is not found: not built, or not sourced."""
    ws = workspace()
    if ws is None:
        return ""
    install = ws.root / "install"
    built = (install / package).is_dir() or (install / overlay.INDEX / package).is_file()
    in_src = any((p.parent.name == package) for p in ws.src.glob("*/package.xml")) or any(
        p.parent.name == package for p in ws.src.glob("*/*/package.xml")
    )
    if built and install not in overlay.sourced():
        return (
            f"\n(hint: {package} is built in your workspace, but this Console has not sourced "
            "it: type `source install/setup.bash`, then try again)"
        )
    if built:
        return (
            f"\n(hint: {package} was built after your last `source`: source "
            "install/setup.bash again, as a new terminal would)"
        )
    if in_src:
        return (
            f"\n(hint: {package} is in src/ but not built: `colcon build --packages-select "
            f"{package}`, then `source install/setup.bash`)"
        )
    return ""


def terminal_argv(package: str, words: list[str]) -> list[str] | None:
    """`ros2-classroom run PKG EXE ...` in a shell that sourced a colcon workspace.

    The executable as upstream's ros2run finds it (``<prefix>/lib/<pkg>/<exe>``
    of the first prefix in AMENT_PREFIX_PATH holding the package), when that
    prefix was built by colcon; None for everything else (catalog names).
    """
    if not words or workspace() is not None:
        return None
    prefix = overlay.package_prefix(package)
    if prefix is None or not (prefix / "share" / "colcon-core").is_dir():
        return None
    executable, rest = words[0], words[1:]
    paths = [p for p in overlay.executables(package, prefix) if p.name == executable]
    if not paths:
        raise Ros2cliMessage("No executable found")
    return [str(paths[0]), *rest]
