"""Benchmark: what recording each graded attempt costs the grading (issue 41).

The same grading (an exercise's reference solution, the same seed, so the same
hidden inputs) runs again and again, alternately with its attempt recorded
(``AttemptStore``: a bag of every topic, the verdict in its metadata, the
plots drawn) and without (the baseline, in the same run, on the same
participant and supervisor). A grading's time runs from ``grade()``'s call to
its report, bag closed and plots written included. The learner's program is
started before each grading and stopped after it, outside the timed span.

``attempt_record_overhead_percent``: for each exercise the median recorded
grading over its median plain one, minus one, in percent; the worse exercise
counts (aim at most 10 %).

``attempt_record_cpu_core_percent``: what recording adds to the CPU of the
grading process (all its threads: the grader, its executor, the recording's
writer), as a share of one core over the recorded grading's time: the
median recorded grading's CPU seconds minus the median plain one's, over the
median recorded grading's seconds. Over the topic feeds and over
``wall_stop`` in the simulated world, whose every topic (about 300 messages a
simulated second, at twice real time) is recorded; the worse exercise counts
(aim at most 10 % of a core; 36 % before the recording took its messages in
batches on a node of its own). The simulated grading's time is not judged:
the world's pace sets it.

Run: ``.venv/bin/python tests/run.py --bench attempt_overhead [--rounds N]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

from bench._common import configure_dds, require_private_netns, rounded

EXERCISES = ("running_sum", "heartbeat_logger")  # topic feeds, log lines: plots drawn too
SIM_EXERCISE = "wall_stop"  # the simulated world: the most topics a recording takes
AIM_PERCENT = 10.0
AIM_CPU_PERCENT = 10.0  # of one core


def _grade_once(
    grader: Any, supervisor: Any, exercise: Any, script: Path, seed: int
) -> tuple[float, float]:
    """(seconds, CPU seconds of this process) of one grading."""
    from app.exercises import runner

    runner.start(supervisor, exercise, script)
    try:
        began, cpu = time.perf_counter(), time.process_time()
        report = grader.grade(exercise, script, seed=seed)
        spent, cpu = time.perf_counter() - began, time.process_time() - cpu
    finally:
        runner.stop(supervisor, exercise)
    if not report.passed:
        raise RuntimeError(f"the reference of {exercise.slug} failed: {report.summary()}")
    if grader.attempts is not None and not report.attempt:
        raise RuntimeError(f"the attempt was not kept: {report.attempt_note}")
    return spent, cpu


def run(rounds: int) -> dict[str, Any]:
    from app.exercises.attempts import AttemptStore
    from app.exercises.grader import Grader
    from app.exercises.model import load_exercises
    from app.ros.runtime import RosRuntime
    from app.supervisor import Supervisor

    book = load_exercises()
    runtime = RosRuntime("bench_attempt_grader")
    supervisor = Supervisor(os.environ)
    figures: dict[str, Any] = {}
    try:
        with tempfile.TemporaryDirectory(prefix="bench_attempts_") as scratch:
            folder = Path(scratch)
            plain = Grader(runtime.node, supervisor)
            recorded = Grader(runtime.node, supervisor, AttemptStore(folder / "attempts"))
            overheads: list[float] = []
            cpu_overheads: list[float] = []
            for slug in (*EXERCISES, SIM_EXERCISE):
                times: dict[str, list[float]] = {"plain": [], "recorded": []}
                cpus: dict[str, list[float]] = {"plain": [], "recorded": []}
                exercise = book.get(slug)
                script = folder / f"{slug}.py"
                script.write_text(exercise.reference, encoding="utf-8")
                # Warm: imports, discovery (and the world started, for the simulated one).
                _grade_once(plain, supervisor, exercise, script, 1)
                for n in range(rounds):  # alternate, so a slower minute hits both sides
                    order = (plain, recorded) if n % 2 == 0 else (recorded, plain)
                    for grader in order:
                        side = "plain" if grader is plain else "recorded"
                        spent, cpu = _grade_once(grader, supervisor, exercise, script, 7)
                        times[side].append(spent)
                        cpus[side].append(cpu)
                        print(f"{slug} {side}: {spent:.3f} s, {cpu:.3f} CPU-s", flush=True)
                p50 = {side: statistics.median(spent) for side, spent in times.items()}
                cpu50 = {side: statistics.median(spent) for side, spent in cpus.items()}
                if slug != SIM_EXERCISE:
                    overheads.append((p50["recorded"] / p50["plain"] - 1.0) * 100.0)
                added = cpu50["recorded"] - cpu50["plain"]
                cpu_overheads.append(100.0 * added / p50["recorded"])
                figures[f"attempt_{slug}_plain_p50_s"] = p50["plain"]
                figures[f"attempt_{slug}_recorded_p50_s"] = p50["recorded"]
                figures[f"attempt_{slug}_plain_cpu_p50_s"] = cpu50["plain"]
                figures[f"attempt_{slug}_recorded_cpu_p50_s"] = cpu50["recorded"]
    finally:
        supervisor.shutdown()
        runtime.shutdown()
    # The worse exercise: each compared with itself (their gradings last 2 s and 7 s).
    figures["attempt_record_overhead_percent"] = max(overheads)
    figures["attempt_record_cpu_core_percent"] = max(cpu_overheads)
    figures["attempt_gradings_per_side"] = rounds * (len(EXERCISES) + 1)
    return figures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench attempt_overhead")
    parser.add_argument("--rounds", type=int, default=4, help="gradings per side and exercise")
    args = parser.parse_args(argv)
    require_private_netns("attempt_overhead")
    configure_dds(61)
    figures = run(max(1, args.rounds))
    overhead = figures["attempt_record_overhead_percent"]
    cpu_overhead = figures["attempt_record_cpu_core_percent"]
    figures["aim_met"] = bool(overhead <= AIM_PERCENT and cpu_overhead <= AIM_CPU_PERCENT)
    for slug in (*EXERCISES, SIM_EXERCISE):
        print(
            f"{slug} grading p50: plain {figures[f'attempt_{slug}_plain_p50_s']:.3f} s "
            f"({figures[f'attempt_{slug}_plain_cpu_p50_s']:.3f} CPU-s), recorded "
            f"{figures[f'attempt_{slug}_recorded_p50_s']:.3f} s "
            f"({figures[f'attempt_{slug}_recorded_cpu_p50_s']:.3f} CPU-s)"
        )
    print(f"time overhead, the worse exercise: {overhead:+.1f} % (aim <= {AIM_PERCENT:g} %)")
    print(
        f"CPU the recording adds, the worse exercise: {cpu_overhead:.1f} % of a core "
        f"(aim <= {AIM_CPU_PERCENT:g} %)"
    )
    print(json.dumps(rounded(figures, 3), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
