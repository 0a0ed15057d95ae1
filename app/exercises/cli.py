"""``ros2-classroom exercise list|starter|solution|check|explain``: grading from a terminal.

For learners who prefer their own editor, for teachers, and for the tests:
``check SLUG FILE`` runs FILE as the exercise's node through the supervisor,
grades it exactly as the dashboard's Check button does, prints one line per
check and exits 0 only when all pass; ``--seed N`` replays a grading's
random inputs. ``explain SLUG`` tells a teacher what is checked and probed,
with the ranges inputs are drawn from, never the values.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from app.exercises.attempt_folders import graded_code, replay_command
from app.exercises.model import Exercise, ExerciseError, load_exercises
from app.exercises.report import Report

if TYPE_CHECKING:
    from app.exercises.attempts import AttemptStore

EXIT_FAILED = 1


def cmd_list(_slug: str | None, _file: Path | None, _seed: int | None = None) -> int:
    book = load_exercises()
    width = max((len(e.slug) for e in book.exercises), default=4)
    for exercise in book.exercises:
        print(f"{exercise.slug:<{width}}  lesson {exercise.unit:>2}  {exercise.title}")
    for error in book.errors:
        print(f"broken exercise: {error}", file=sys.stderr)
    return 0


def cmd_starter(slug: str | None, _file: Path | None, _seed: int | None = None) -> int:
    print(load_exercises().get(slug or "").starter, end="")
    return 0


def cmd_solution(slug: str | None, _file: Path | None, _seed: int | None = None) -> int:
    print(load_exercises().get(slug or "").reference, end="")
    return 0


def cmd_explain(slug: str | None, _file: Path | None, _seed: int | None = None) -> int:
    from app.exercises.explain import explain

    print("\n".join(explain(load_exercises().get(slug or ""))))
    return 0


def cmd_check(slug: str | None, file: Path | None, seed: int | None = None) -> int:
    from app.exercises import runner
    from app.exercises.grader import Grader
    from app.exercises.lint import lint, refuses_to_run
    from app.ros.runtime import RosRuntime
    from app.supervisor import Supervisor

    exercise = load_exercises().get(slug or "")
    assert file is not None
    if exercise.is_package:
        return _check_package(exercise, file, seed)
    try:
        code = file.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ExerciseError(f"cannot read {file}: {exc}") from None
    problems = lint(code, file.name)
    for problem in problems:
        print(f"{file}:{problem.line}:{problem.column + 1}: {problem.message}")
    if refuses_to_run(problems):
        print(f"FAIL  {exercise.slug}: not run, fix the syntax error first")
        return EXIT_FAILED
    runtime = RosRuntime("classroom_grader")
    supervisor = Supervisor(os.environ)
    try:
        runner.start(supervisor, exercise, file.resolve())
        report = Grader(runtime.node, supervisor, _attempts()).grade(
            exercise, file.resolve(), on_result=lambda r: print(r.line(), flush=True), seed=seed
        )
    finally:
        supervisor.shutdown(timeout=3.0)
        runtime.shutdown()
    return _print_verdict(exercise, report, file)


def _check_package(exercise: Exercise, folder: Path, seed: int | None) -> int:
    """FILE is the package folder (~/ros2_ws/src/PKG): built, started and graded."""
    import tempfile

    from app.exercises.grader import Grader
    from app.exercises.package_grading import grade_package
    from app.ros.runtime import RosRuntime
    from app.supervisor import Supervisor

    if not (folder / "package.xml").is_file():
        raise ExerciseError(
            f"{folder}: `exercise check {exercise.slug}` grades a package folder "
            f"(your {exercise.package} in ~/ros2_ws/src), and this one has no package.xml"
        )
    runtime = RosRuntime("classroom_grader")
    supervisor = Supervisor(os.environ)
    try:
        with tempfile.TemporaryDirectory(prefix="classroom_grading_") as scratch:
            report = grade_package(
                Grader(runtime.node, supervisor, _attempts()),
                exercise,
                folder.resolve(),
                Path(scratch),
                on_result=lambda r: print(r.line(), flush=True),
                seed=seed,
            )
    finally:
        supervisor.shutdown(timeout=3.0)
        runtime.shutdown()
    return _print_verdict(exercise, report, folder)


def _attempts() -> AttemptStore:
    """Kept where the dashboard keeps them (imported here: it needs ROS)."""
    from app.exercises.attempts import AttemptStore, attempts_root

    return AttemptStore(attempts_root())


def _print_verdict(exercise: Exercise, report: Report, graded: Path) -> int:
    """The last lines of a check, and its exit status; a replay line for a seeded grading;
    where the attempt and the plots of what was judged were kept."""
    if report.problem:
        print(f"FAIL  {exercise.slug}: {report.problem}")
    print(report.summary())
    if report.attempt:
        print(f"recorded: {report.attempt}")
    if report.attempt_note:
        print(report.attempt_note)
    for plot in report.plots:
        print(f"plot: {plot}")
    if report.seed is not None and not report.problem:
        # The copy kept with the attempt, when there is one: FILE may change after this.
        kept = graded_code(Path(report.attempt)) if report.attempt else None
        print(f"replay: {replay_command(exercise.slug, kept or graded, report.seed)}")
    return 0 if report.passed else EXIT_FAILED


VERBS = {
    "list": cmd_list,
    "starter": cmd_starter,
    "solution": cmd_solution,
    "check": cmd_check,
    "explain": cmd_explain,
}


def main(verb: str, slug: str | None, file: Path | None, seed: int | None = None) -> int:
    if verb in ("starter", "solution", "check", "explain") and not slug:
        raise ExerciseError(f"`exercise {verb}` needs an exercise name (see `exercise list`)")
    if verb == "check" and file is None:
        raise ExerciseError("`exercise check SLUG FILE` needs the file to grade")
    return VERBS[verb](slug, file, seed)
