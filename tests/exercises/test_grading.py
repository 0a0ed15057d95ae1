"""Grading every exercise on the live graph: the reference and the accepted
alternative solutions (``accepted/``, written differently on purpose) pass; the
starter, each recorded mistake and a generated cheat (it replays the statement's
example) fail, and a mistake's failure names what is wrong.

One ROS participant and one supervisor serve the whole module (each exercise
runs as a real process, as the Run button starts it). Exercises use distinct
node names, and every learner process is stopped after its case.

The exercise's setup (the world, turtlesim, Nav2...) runs on from one case to the next
of the same exercise, as it does for a learner between two attempts (the grader starts
it if it is not running and leaves it on); it is stopped when the next case is another
exercise's. So a grading is tried both on a fresh setup and on one an earlier attempt
left as it was (a Nav2 goal still driving, a turtle the last program spawned), and the
module does not start the same world a few times over.
"""

from __future__ import annotations

import contextlib
import re
import shutil
from pathlib import Path

import psutil
import pytest

from app.exercises import runner
from app.exercises.attempts import AttemptStore
from app.exercises.grader import Grader
from app.exercises.model import Exercise
from app.exercises.package_grading import grade_package
from app.exercises.report import Report
from tests.bags.readers import mcap_messages
from tests.conftest import fail_on_leftover_nodes
from tests.course_data import shared_exercises
from tests.exercises.cheats import EXEMPT, cheat_code
from tests.exercises.grading_participant import grading_participant

pytestmark = pytest.mark.ros  # each case runs a learner program over DDS

BOOK = shared_exercises()
# Correct solutions written differently from the references: accepted/<slug>__<how>.py.
ACCEPTED = Path(__file__).parent / "accepted"


def _cases():
    for exercise in BOOK.exercises:
        yield pytest.param(exercise, "reference", None, id=f"{exercise.slug}-reference")
        yield pytest.param(exercise, "starter", None, id=f"{exercise.slug}-starter")
        if exercise.slug not in EXEMPT:  # no generator and no exemption: the case fails
            yield pytest.param(exercise, "cheat", None, id=f"{exercise.slug}-cheat")
        for path in sorted(ACCEPTED.glob(f"{exercise.slug}__*.py")):
            yield pytest.param(exercise, "accepted", path, id=path.stem)
        for mistake in exercise.mistakes:
            # A package mistake is a folder named for the package: its parent names the mistake.
            name = mistake.path.parent.name if exercise.is_package else mistake.path.stem
            yield pytest.param(exercise, "mistake", mistake, id=f"{exercise.slug}-{name}")


@pytest.fixture(scope="module")
def grading_env(tmp_path_factory):
    with grading_participant("exercise_grader_test", domain_id=77) as (node, supervisor):
        # Every grading recorded, as the dashboard does: each attempt is read back below.
        attempts = AttemptStore(tmp_path_factory.mktemp("attempts"))
        yield Grader(node, supervisor, attempts), supervisor, tmp_path_factory.mktemp("code")
        _stop_setup(supervisor)


# The exercise whose setup the module's supervisor runs now (see the module's docstring).
_setup_of: list[Exercise] = []


def _stop_setup(supervisor) -> None:
    """Stop the running setup (each node still Ctrl+C, then escalated), all at once."""
    if _setup_of:
        stopping = [supervisor.stop(name) for name in _setup_of.pop().setup]
        for future in stopping:
            future.result()


def _switch_to(exercise: Exercise, supervisor) -> None:
    """Another exercise's case: the last one's setup stops first, and leaves nothing."""
    if _setup_of and _setup_of[-1] is not exercise:
        _stop_setup(supervisor)
        fail_on_leftover_nodes("the last exercise's setup")
    _setup_of[:] = [exercise]


def _setup_pids(supervisor, exercise: Exercise) -> set[int]:
    """The running setup's processes and theirs (a launch file's nodes)."""
    pids: set[int] = set()
    for status in supervisor.statuses().values():
        if status.name in exercise.setup and status.active and status.pid:
            pids.add(status.pid)
            with contextlib.suppress(psutil.Error):
                pids.update(c.pid for c in psutil.Process(status.pid).children(recursive=True))
    return pids


def _read_back(report: Report, ran: bool = True) -> Report:
    """The grading's attempt is kept, and the independent MCAP reader reads all of it.

    ``ran`` False: a package that may not have built, so never ran (nothing to record).
    """
    if not ran and not (report.attempt or report.attempt_note):
        return report
    assert report.attempt, f"the attempt was not kept: {report.attempt_note}"
    verdict = "problem" if report.problem else ("pass" if report.passed else "fail")
    assert report.attempt.endswith(f"-seed7-{verdict}"), report.attempt
    mcap_messages(Path(report.attempt))  # raises on a damaged file or an undecodable message
    _plots_agree(report)
    return report


def _plots_agree(report: Report) -> None:
    """What a result plots agrees with its verdict, and the attempt keeps each plot as a PNG.

    A passed result marks no moment; a failed one marks where its last trace was lost,
    and for "closer than the bound" no later than the moment its line names.
    """
    for result in report.results:
        for trace in result.traces:
            assert trace.values, f"{result.name}: a trace with nothing in it"
        marked = [t for t in result.traces if t.broken_at is not None]
        if result.passed:
            assert not marked, f"{result.name} passed, yet its plot marks {marked[0].broken_why}"
        elif result.traces:
            last = result.traces[-1]
            assert last.broken_at is not None, f"{result.name} failed: {result.detail}"
            near = re.search(r"of the wall ahead at (\d+\.\d) s: closer", result.detail)
            if near:
                assert last.broken_at <= float(near.group(1)) + 0.05, (last.broken_at, near[0])
    drawn = [Path(p) for p in report.plots]
    assert len(drawn) == len(report.traces()), (report.plots, report.attempt)
    for path in drawn:
        assert path.parent == Path(report.attempt) and path.read_bytes()[:8] == PNG, path


PNG = b"\x89PNG\r\n\x1a\n"


def _grade(grading_env, exercise: Exercise, code: str) -> Report:
    grader, supervisor, scratch = grading_env
    _switch_to(exercise, supervisor)
    script = scratch / f"{exercise.slug}.py"
    script.write_text(code, encoding="utf-8")
    runner.start(supervisor, exercise, script)
    try:
        return _read_back(grader.grade(exercise, script, seed=7))
    finally:
        # The verdict is in: the learner's program ends, as a learner's Stop ends it;
        # the setup runs on for the next attempt.
        runner.stop(supervisor, exercise)
        # Nothing else left running, e.g. the nodes a launch file started.
        fail_on_leftover_nodes("this case", kept=_setup_pids(supervisor, exercise))


def _grade_package(grading_env, exercise: Exercise, folder: Path) -> Report:
    """A package exercise: the grader builds the folder with colcon, then runs or launches it."""
    grader, supervisor, scratch = grading_env
    _switch_to(exercise, supervisor)
    try:
        return _read_back(grade_package(grader, exercise, folder, scratch, seed=7), ran=False)
    finally:
        fail_on_leftover_nodes("this case")


def _package_source(exercise: Exercise, which: str, mistake, scratch: Path) -> Path:
    if which == "mistake":
        return mistake.path
    if which != "cheat":
        folder = exercise.reference_dir if which == "reference" else exercise.starter_dir
        assert folder is not None
        return folder
    # The cheat: the reference package with its node module replaced by the replayer.
    assert exercise.reference_dir is not None
    folder = scratch / "cheat" / exercise.reference_dir.name
    shutil.rmtree(folder, ignore_errors=True)
    shutil.copytree(exercise.reference_dir, folder)
    (folder / exercise.main_file).write_text(cheat_code(exercise), encoding="utf-8")
    return folder


def _text(report: Report) -> str:
    return "\n".join([report.problem, *(r.line() for r in report.results)])


@pytest.mark.parametrize(("exercise", "which", "mistake"), list(_cases()))
def test_grading(grading_env, exercise, which, mistake):
    if exercise.is_package:
        source = _package_source(exercise, which, mistake, grading_env[2])
        report = _grade_package(grading_env, exercise, source)
        expected = mistake.reason if mistake is not None else ""
        _judge(exercise, which, report, expected)
    elif which == "reference":
        report = _grade(grading_env, exercise, exercise.reference)
        assert report.passed, _text(report)
    elif which == "accepted":
        report = _grade(grading_env, exercise, mistake.read_text(encoding="utf-8"))
        assert report.passed, f"a correct solution written differently fails:\n{_text(report)}"
    elif which == "starter":
        report = _grade(grading_env, exercise, exercise.starter)
        assert not report.passed, "the starter code passes: the exercise asks for nothing"
    elif which == "cheat":
        report = _grade(grading_env, exercise, cheat_code(exercise))
        assert not report.passed, f"replaying the statement's example passes:\n{_text(report)}"
        assert report.seed == 7 and "seed 7" in report.summary()
    else:
        report = _grade(grading_env, exercise, mistake.path.read_text(encoding="utf-8"))
        assert not report.passed, f"{mistake.path.name} passes:\n{_text(report)}"
        failing = "\n".join([report.problem, *(r.detail for r in report.failures())])
        assert mistake.reason in failing, (
            f"{mistake.path.name} fails, but not for the recorded reason {mistake.reason!r}:\n"
            + _text(report)
        )


def _judge(exercise: Exercise, which: str, report: Report, reason: str) -> None:
    """The same verdicts as for a single file, for a graded package."""
    if which == "reference":
        assert report.passed, _text(report)
        return
    assert not report.passed, f"{exercise.slug} {which} passes:\n{_text(report)}"
    failing = "\n".join([report.problem, *(r.detail for r in report.failures())])
    assert reason in failing, f"not for the recorded reason {reason!r}:\n{_text(report)}"
