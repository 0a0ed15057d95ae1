"""Grading a package the learner builds: colcon build, then `ros2 run` or `ros2 launch` it.

A package exercise grades the learner's ROS package, not one file. The
grader copies the package folder into a fresh colcon workspace of its own
(so nothing of the learner's workspace is touched or reused), builds it with
the same colcon the Console runs (``app.learner_ws.build``: options fixed,
files capped, time bounded), and starts what the exercise names exactly as
``ros2 run PACKAGE EXECUTABLE`` or ``ros2 launch PACKAGE FILE`` would find
it in the install space. Each of these steps is a result line: a build that
fails, an executable that was never installed, a launch file left out of
``data_files`` are what the learner reads, never a crash. Then the usual
checks and probes run on the live graph (``app.exercises.grader``).

A build runs the learner's setup.py, i.e. their code: it follows the rule for
their other code. On their own machine it runs as they would run it; on a
dashboard served to other machines only with the teacher's consent, and then
contained (the build, and the node it installed).
"""

from __future__ import annotations

import dataclasses
import os
import shutil
import sys
import time
from collections.abc import Callable
from pathlib import Path

from app.containment.policy import LOOPBACK_POLICY, RunPolicy, RunRefused
from app.exercises import runner
from app.exercises.grader import Grader
from app.exercises.model import Exercise, package_files
from app.exercises.report import Report, Result
from app.learner_ws import build, folder, served
from app.learner_ws.folder import BuildLimits, LearnerWorkspace
from app.ros.errors import Ros2Error
from app.supervisor import LearnerProgram, Supervisor

# An exercise package (ament_python) builds in a few seconds; a setup.py that loops does not.
BUILD_SECONDS = 120.0
DISK_BYTES = 256 * 1024**2  # build/ install/ log/ of one exercise package
POLL_SEC = 0.2
STDERR_LINES = 20  # of a failed build, shown in the result


def _copy_package(source: Path, workspace: Path) -> Path:
    """``workspace/src/<folder>``: a fresh copy of the package's files (no build products)."""
    if workspace.exists():
        shutil.rmtree(workspace)
    target = workspace / "src" / source.name
    for path in package_files(source):
        destination = target / path.relative_to(source)
        destination.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(path, destination)
    return target


def _build(
    supervisor: Supervisor, exercise: Exercise, ws: LearnerWorkspace, policy: RunPolicy
) -> Result:
    """colcon build in the grader's workspace, waited for; the result names what failed."""
    name = f"{build.PROGRAM_PREFIX}exercise:{exercise.slug}"
    try:
        program = dataclasses.replace(served.colcon_program(ws, ["build"], policy), name=name)
    except build.BuildRefused as exc:
        return Result("colcon build", False, str(exc))
    started = time.monotonic()
    supervisor.start_program(program)
    while supervisor.status(name).active:
        too_long = time.monotonic() - started > ws.limits.seconds
        too_big = build.disk_usage(ws.root) > ws.limits.disk_bytes
        if too_long or too_big:
            supervisor.stop(name).result(timeout=15.0)
            limit = (
                f"ran longer than {ws.limits.seconds:g} s (does setup.py loop forever?)"
                if too_long
                else f"wrote more than {ws.limits.disk_bytes // 2**20} MiB"
            )
            return Result(
                "colcon build", False, f"the build {limit}, the limit here, and was stopped"
            )
        time.sleep(POLL_SEC)
    status = supervisor.status(name)
    lines = supervisor.output(name)
    seconds = time.monotonic() - started
    if status.exit_code == 0 and (ws.root / "install" / exercise.package).is_dir():
        return Result("colcon build", True, f"{exercise.package} built in {seconds:.1f} s")
    unread = any("package identification" in line and "ERROR" in line for line in lines)
    if status.exit_code == 0 and unread:  # colcon skipped the package: its setup.py failed
        shown = "\n".join(build.build_errors(lines, ws)[:STDERR_LINES])
        return Result("colcon build", False, f"colcon could not read your setup.py:\n{shown}")
    if status.exit_code == 0:
        return Result(
            "colcon build",
            False,
            f"colcon found no package named {exercise.package} (is <name> in package.xml "
            f"{exercise.package}?); it built: "
            + (", ".join(p.name for p in (ws.root / "install").iterdir() if p.is_dir()) or "none"),
        )
    shown = "\n".join(build.build_errors(lines, ws)[:STDERR_LINES])
    return Result(
        "colcon build", False, f"the build failed (exit code {status.exit_code}):\n{shown}"
    )


def _python_dirs(prefix: Path) -> list[str]:
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    found = [prefix / "lib" / version / "site-packages", prefix / "local" / "lib" / version]
    return [str(p) for p in found if p.is_dir()]


def _sourced_env(prefix: Path, base: dict[str, str] | None = None) -> dict[str, str]:
    """What `source install/setup.bash` gives a program: this prefix in front of the paths."""
    base = dict(os.environ) if base is None else base

    def front(name: str, paths: list[str]) -> str:
        rest = [p for p in base.get(name, "").split(os.pathsep) if p and p not in paths]
        return os.pathsep.join(paths + rest)

    return {
        "AMENT_PREFIX_PATH": front("AMENT_PREFIX_PATH", [str(prefix)]),
        "PYTHONPATH": front("PYTHONPATH", _python_dirs(prefix)),
    }


def _program(exercise: Exercise, ws: LearnerWorkspace, policy: RunPolicy) -> LearnerProgram:
    """What `ros2 run`/`ros2 launch` would start from the install space, or RunRefused."""
    prefix = ws.root / "install" / exercise.package
    if exercise.run:
        folder = prefix / "lib" / exercise.package
        path = folder / exercise.run
        if not (path.is_file() and os.access(path, os.X_OK)):
            present = sorted(p.name for p in folder.iterdir()) if folder.is_dir() else []
            raise RunRefused(
                "No executable found: the build installed "
                + (", ".join(present) if present else "no executable")
                + f" in lib/{exercise.package}; `ros2 run` needs a console_scripts line "
                f"'{exercise.run} = {exercise.package}.MODULE:main' in setup.py"
            )
        program = LearnerProgram(
            exercise.program_name,
            exercise.node,
            (str(path),),
            ws.root,
            env=_sourced_env(prefix),
        )
        try:
            return served.node_program(ws, program, policy)
        except Ros2Error as exc:
            raise RunRefused(str(exc)) from None
    share = prefix / "share" / exercise.package
    found = sorted(share.rglob(exercise.launch)) if share.is_dir() else []
    if not found:
        raise RunRefused(
            f"file '{exercise.launch}' was not found in the share directory of package "
            f"'{exercise.package}' ({share}): setup.py's data_files must install the launch "
            "folder into share/<package>/launch"
        )
    from app.launch_prefix import LaunchRefused, launch_program

    try:
        program = launch_program(
            exercise.program_name, exercise.node, [str(found[0])], ws.root, policy, trusted=False
        )
    except LaunchRefused as exc:
        raise RunRefused(str(exc)) from None
    env = dict(program.env or {})
    return dataclasses.replace(program, env={**env, **_sourced_env(prefix, {**os.environ, **env})})


def grade_package(
    grader: Grader,
    exercise: Exercise,
    source: Path,
    scratch: Path,
    *,
    policy: RunPolicy = LOOPBACK_POLICY,
    on_result: Callable[[Result], None] | None = None,
    seed: int | None = None,
) -> Report:
    """Build ``source`` (a package folder), start it, grade it; the learner's process is
    stopped before this returns."""
    supervisor = grader.supervisor
    results: list[Result] = []

    def record(result: Result) -> None:
        results.append(result)
        if on_result is not None:
            on_result(result)

    if not policy.allowed:
        return Report(exercise.slug, problem=policy.refusal(), seed=seed)
    if not (source / "package.xml").is_file():
        return Report(exercise.slug, problem=f"{source} is not a package folder (no package.xml)")
    limits = BuildLimits(seconds=BUILD_SECONDS, disk_bytes=DISK_BYTES)
    group = None
    if policy.contained:  # served: built and run like the learner's other code, contained
        from app.containment.contain import SANDBOX_GID

        group = SANDBOX_GID
    workspace = LearnerWorkspace(
        scratch / f"{exercise.slug}_ws", remote=policy.contained, limits=limits, group=group
    )
    _copy_package(source, workspace.root)
    built = _build(supervisor, exercise, workspace.ensure(), policy)
    record(built)
    if not built.passed:
        return Report(exercise.slug, results, seed=seed)
    how = f"ros2 {'run' if exercise.run else 'launch'} {exercise.package} "
    how += exercise.run or exercise.launch
    try:
        program = _program(exercise, workspace, policy)
    except RunRefused as exc:
        record(Result(how, False, str(exc)))
        return Report(exercise.slug, results, seed=seed)
    record(Result(how, True, "started"))
    script = workspace.root / "src" / source.name / exercise.main_file
    if (
        exercise.program_name in supervisor.statuses()
        and supervisor.status(exercise.program_name).active
    ):
        supervisor.stop(exercise.program_name).result()
    supervisor.start_program(program)
    try:
        report = grader.grade(exercise, script, on_result=on_result, seed=seed)
    finally:
        runner.stop(supervisor, exercise)
    report.results[:0] = results
    return report


def run_hint(exercise: Exercise) -> str:
    """What the Run button says for a package exercise: the learner runs it in the Console."""
    how = (
        f"ros2 run {exercise.package} {exercise.run}"
        if exercise.run
        else (f"ros2 launch {exercise.package} {exercise.launch}")
    )
    return (
        f"This exercise grades your package `{exercise.package}` in ~/ros2_ws/src. Try it in "
        f"the Console tab: `colcon build --packages-select {exercise.package}`, "
        f"`source install/setup.bash`, `{how}`. **Check** builds and starts it by itself."
    )


def grade_learner_package(
    grader: Grader,
    exercise: Exercise,
    scratch: Path,
    policy: RunPolicy,
    on_result: Callable[[Result], None] | None = None,
) -> Report:
    """The Check button: the package of that name in the learner's workspace src/."""
    ws = folder.current()
    if ws is None:
        return Report(exercise.slug, problem="this dashboard has no learner workspace")
    source = next(
        (
            p.parent
            for p in sorted(ws.src.glob("**/package.xml"))
            if p.parent.name == exercise.package
        ),
        None,
    )
    if source is None:
        return Report(
            exercise.slug,
            problem=f"no package {exercise.package} in ~/ros2_ws/src yet: create it in the "
            "Console with `ros2 pkg create --build-type ament_python --license Apache-2.0 "
            f"{exercise.package}`",
        )
    return grade_package(grader, exercise, source, scratch, policy=policy, on_result=on_result)
