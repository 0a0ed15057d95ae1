"""Grades a learner's running node: the lessons' checks, then the exercise's probes.

The learner's program must already run (the Run button, or ``exercise
check`` which starts it). The grader starts the exercise's setup nodes,
waits for the learner's node on the graph, evaluates each check until it
passes or its time runs out, then runs each probe. Blocking: call it from a
job thread, never a viser callback or the executor thread. Results are
handed to ``on_result`` as they come, so a page can show progress.
"""

from __future__ import annotations

import dataclasses
import random
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

from rclpy.node import Node

from app.exercises import runner
from app.exercises.attempts import AttemptStore
from app.exercises.check_traces import check_traces
from app.exercises.model import Exercise
from app.exercises.probes import ProbeContext, run_probe
from app.exercises.report import Report, Result
from app.exercises.starting import StartingWatch
from app.lessons.runtime import PASS, LessonRuntime
from app.lessons.schema import LEARNER_PROGRAM, Spec
from app.ros.context import CallContext, Limits
from app.ros.errors import Cancelled
from app.ros.graph import snapshot
from app.supervisor import LearnerProgram, Supervisor

# A check that has not passed by then fails with its last reason; a rate check
# needs about 4 s of messages after discovery, with room for a loaded machine.
CHECK_WAIT_SEC = 10.0
# A fresh process needs a few seconds to import rclpy and join; a launch file's program
# imports twice (ros2 launch, then its nodes). On a loaded machine either can take longer
# (ci100: a launched robot_state_publisher not joined 10 s after Run), so the wait goes
# on while the program's processes still work, up to NODE_WAIT_MAX_SEC.
NODE_WAIT_SEC = 10.0
NODE_WAIT_MAX_SEC = 60.0
POLL_SEC = 0.2
# A learner's service gets 5 s to answer a probe: 3 s was missed by sound nodes at load 25-30.
PROBE_LIMITS = Limits(service_timeout=5.0, action_timeout=30.0)


def _check_name(check: Spec) -> str:
    subject = next(
        (
            check.get(k)
            for k in ("node", "topic", "service", "action", "name", "type")
            if k in check.fields
        ),
        "",
    )
    if check.kind == "log_contains":  # "log of your node contains 'beat 3'"
        who = check.get("catalog_node")
        who = "your node" if who == LEARNER_PROGRAM else who
        return f"log of {who} contains {check.get('text')!r}"
    return f"{check.kind.replace('_', ' ')} {subject}".strip()


class _Programs:
    """The grading's processes, for probes that restart the learner's program (``Programs``).

    A restart keeps how the program was started (contained or not, a launch
    file through ros2 launch) and appends the arguments.
    """

    def __init__(self, supervisor: Supervisor, exercise: Exercise) -> None:
        self.supervisor, self.exercise = supervisor, exercise
        entry = supervisor.program(exercise.program_name)
        self.entry = entry if isinstance(entry, LearnerProgram) else None

    def restart_learner(self, args: Sequence[str]) -> None:
        if self.entry is None:
            raise ValueError("the learner's program was not started by this supervisor")
        name = self.exercise.program_name
        self.supervisor.stop(name).result()
        argv = (*self.entry.argv, *args)
        self.supervisor.start_program(dataclasses.replace(self.entry, argv=argv))

    def learner_alive(self) -> bool:
        status = runner.status(self.supervisor, self.exercise)
        return status is not None and status.active

    def learner_output(self) -> list[str]:
        return runner.output(self.supervisor, self.exercise)

    def stop_setup(self) -> None:
        for future in [self.supervisor.stop(name) for name in self.exercise.setup]:
            future.result()

    def start_setup(self) -> None:
        for name in self.exercise.setup:
            self.supervisor.start(name)

    def setup_output(self) -> dict[str, list[str]]:
        return {name: self.supervisor.output(name) for name in self.exercise.setup}


class Grader:
    def __init__(
        self, node: Node, supervisor: Supervisor, attempts: AttemptStore | None = None
    ) -> None:
        """``attempts``: where each grading is recorded as a bag (None: not recorded)."""
        self.node = node
        self.supervisor = supervisor
        self.attempts = attempts

    def grade(
        self,
        exercise: Exercise,
        script: Path,
        on_result: Callable[[Result], None] | None = None,
        ctx: CallContext | None = None,
        seed: int | None = None,
    ) -> Report:
        # Hidden inputs: drawn for this grading, from a seed the result shows (replayable).
        seed = seed if seed is not None else random.SystemRandom().randrange(1, 1_000_000)
        report = Report(exercise.slug, seed=seed)
        call = ctx or CallContext(self.node, limits=PROBE_LIMITS)
        lessons = LessonRuntime(self.node, self.supervisor)
        recording = self.attempts.start(self.node, exercise.slug) if self.attempts else None

        def record(result: Result) -> None:
            report.results.append(result)
            if on_result is not None:
                on_result(result)

        def for_learner(spec: Spec) -> Spec:
            if spec.get("catalog_node") == LEARNER_PROGRAM:
                return Spec(spec.kind, {**spec.fields, "catalog_node": exercise.program_name})
            return spec

        def wait_checks(specs: Sequence[Spec], timeout: float) -> Iterator[tuple[bool, str]]:
            """Each check's verdict, in order: passed as soon as it passes, failed once
            ``timeout`` has gone by. All are watched at once, so a program that fails
            several is told so after one wait, not one wait per check."""
            pending = {i: for_learner(spec) for i, spec in enumerate(specs)}
            verdicts: dict[int, tuple[bool, str]] = {}
            deadline = time.monotonic() + timeout
            told = 0
            while True:
                lessons.graph = snapshot(self.node)
                late = time.monotonic() > deadline
                for index, spec in list(pending.items()):
                    outcome = lessons.evaluate(spec)
                    if outcome.state == PASS or late:
                        verdicts[index] = (outcome.state == PASS, outcome.reason)
                        del pending[index]
                while told in verdicts:  # in the exercise's order, as soon as known
                    yield verdicts[told]
                    told += 1
                if not pending:
                    return
                call.sleep(POLL_SEC)

        def wait_check(spec: Spec, timeout: float) -> tuple[bool, str]:
            return next(wait_checks([spec], timeout))

        try:
            report.problem = self._wait_for_learner(exercise, script, call)
            if report.problem:
                return report
            verdicts = wait_checks(exercise.checks, CHECK_WAIT_SEC)
            for check, (passed, detail) in zip(exercise.checks, verdicts, strict=True):
                traces = check_traces(lessons, for_learner(check), passed, detail)
                record(Result(_check_name(check), passed, detail, traces))
            programs = _Programs(self.supervisor, exercise)
            probe_ctx = ProbeContext(
                call,
                exercise.node,
                wait_check,
                random.Random(seed),
                seed,
                programs,
                exercise.example,
            )
            for probe in exercise.probes:
                record(run_probe(probe_ctx, probe))
                if not self._alive(exercise):
                    report.problem = self._crash_text(exercise, script, "during the probes")
                    break
        except Cancelled:
            report.problem = "grading was stopped"
        finally:
            lessons.close()
            if recording is not None:
                kept = recording.finish(report, script, package=exercise.is_package)
                report.attempt = str(kept.path or "")
                report.attempt_note = kept.note
                report.plots = [str(path) for path in kept.plots]
        return report

    def _alive(self, exercise: Exercise) -> bool:
        status = runner.status(self.supervisor, exercise)
        return status is not None and status.active

    def _crash_text(self, exercise: Exercise, script: Path, when: str) -> str:
        status = runner.status(self.supervisor, exercise)
        state = status.describe() if status else "not started"
        crash = runner.crash_of(self.supervisor, exercise, script)
        text = f"your program ended {when}: {state}"
        return text + (f"\n{crash.describe()}" if crash else "")

    def _wait_for_learner(self, exercise: Exercise, script: Path, call: CallContext) -> str:
        """'' once the learner's node is on the graph, else why grading cannot start."""
        if runner.status(self.supervisor, exercise) is None:
            return "your program is not running: click Run first"
        for name in exercise.setup:
            self.supervisor.start(name)
        started = time.monotonic()
        busy = StartingWatch()
        while True:
            status = runner.status(self.supervisor, exercise)
            if status is None or not status.active:
                return self._crash_text(exercise, script, "before it could be graded")
            graph = snapshot(self.node)
            setup_nodes = [self.supervisor.status(n) for n in exercise.setup]
            if graph.has_node(exercise.node) and all(s.active for s in setup_nodes):
                return ""
            waited = time.monotonic() - started
            starting = busy.still_starting(status.pid)
            if waited > NODE_WAIT_MAX_SEC or (waited > NODE_WAIT_SEC and not starting):
                seen = ", ".join(n for n in graph.nodes) or "none"
                return (
                    f"your program runs, but no node {exercise.node} joined the graph within "
                    f"{waited:.0f} s (nodes seen: {seen}). Check the name you give Node()."
                )
            call.sleep(POLL_SEC)
