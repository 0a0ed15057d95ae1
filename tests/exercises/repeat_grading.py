"""Grade every case many times over, on a loaded machine: are grades stable?

Run through the private network namespace:
``.venv/bin/python tests/run.py --script tests/exercises/repeat_grading.py --runs 5``.
For each exercise: the reference and the accepted alternative solutions must pass; each
recorded mistake and the generated cheat (it replays the statement's example) must fail.
Exercises judged on a rate (a topic_rate check, a log_rate probe, a rate that follows a
parameter) are graded ``--rate-runs`` times, the others ``--runs`` times. Every grading
draws a fresh seed (printed with any wrong grade, to replay it).

Load: ``--burn N`` keeps N busy-looping processes running; ``--load-cmd CMD`` runs CMD
in a loop meanwhile (a second test job, e.g. ``python tests/run.py tests/faults -q``).
Both are ended by their process group at the end. The 1-minute load average is sampled
at every case. Writes a JSON summary to ``--out``.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from app.exercises import runner
from app.exercises.model import Exercise
from tests.course_data import shared_exercises
from tests.exercises.cheats import EXEMPT, cheat_code

BURN = "import time\nwhile True:\n    sum(i * i for i in range(10000)); time.sleep(0.001)\n"
ACCEPTED = Path(__file__).parent / "accepted"


def rate_judged(exercise: Exercise) -> bool:
    """Judged on a rate: a topic_rate check, a log_rate probe, or a rate after a parameter."""
    if any(c.kind == "topic_rate" for c in exercise.checks):
        return True
    for probe in exercise.probes:
        if probe.kind == "log_rate":
            return True
        then = probe.get("then") if probe.kind == "param_set" else None
        if isinstance(then, dict) and "expect_hz" in then:
            return True
    return False


def cases(
    exercise: Exercise, which: str, scratch: Path
) -> list[tuple[str, str, bool, Path | None]]:
    """(name, code, should pass, package folder) for every case of ``exercise``."""
    out: list[tuple[str, str, bool, Path | None]] = []
    if which in ("reference", "all"):
        out.append(("reference", exercise.reference, True, exercise.reference_dir))
    if which in ("accepted", "all") and not exercise.is_package:
        for path in sorted(ACCEPTED.glob(f"{exercise.slug}__*.py")):
            out.append((path.stem.split("__", 1)[1], path.read_text(), True, None))
    if which in ("mistakes", "all"):
        for m in exercise.mistakes:
            if exercise.is_package:
                out.append((m.path.parent.name, "", False, m.path))
            else:
                out.append((m.path.stem, m.path.read_text(), False, None))
    if which in ("cheats", "all") and exercise.slug not in EXEMPT:
        if exercise.is_package:
            assert exercise.reference_dir is not None
            folder = scratch / "cheat" / exercise.reference_dir.name
            shutil.rmtree(folder, ignore_errors=True)
            shutil.copytree(exercise.reference_dir, folder)
            (folder / exercise.main_file).write_text(cheat_code(exercise))
            out.append(("cheat", "", False, folder))
        else:
            out.append(("cheat", cheat_code(exercise), False, None))
    return out


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--rate-runs", type=int, default=20)
    parser.add_argument("--slugs", nargs="*", default=None)
    parser.add_argument(
        "--which", choices=("reference", "accepted", "mistakes", "cheats", "all"), default="all"
    )
    parser.add_argument("--burn", type=int, default=0)
    parser.add_argument("--load-cmd", default="", help="run this in a loop meanwhile")
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()

    from app.dds import configure_dds_env
    from app.exercises.grader import Grader
    from app.exercises.package_grading import grade_package
    from app.ros.runtime import RosRuntime
    from app.supervisor import Supervisor

    configure_dds_env(os.environ, domain_id=60 + os.getpid() % 30, network=False)
    book = shared_exercises()
    exercises = [e for e in book.exercises if args.slugs is None or e.slug in args.slugs]
    burners = [
        subprocess.Popen([sys.executable, "-c", BURN], start_new_session=True)
        for _ in range(args.burn)
    ]
    if args.load_cmd:
        loop = f"while true; do {args.load_cmd} > /dev/null 2>&1; done"
        burners.append(subprocess.Popen(["/bin/sh", "-c", loop], start_new_session=True))
    runtime = RosRuntime("repeat_grader")
    supervisor = Supervisor(os.environ)
    grader = Grader(runtime.node, supervisor)
    scratch = Path(tempfile.mkdtemp(prefix="repeat_grading_"))
    figures: dict[str, dict[str, object]] = {}
    loads: list[float] = []
    started = time.monotonic()
    try:
        for exercise in exercises:
            runs = args.rate_runs if rate_judged(exercise) else args.runs
            for name, code, should_pass, folder in cases(exercise, args.which, scratch):
                right, wrong_seeds = 0, []
                for _ in range(runs):
                    loads.append(os.getloadavg()[0])
                    seed = random.SystemRandom().randrange(1, 1_000_000)
                    if exercise.is_package:  # built with colcon, then run or launched
                        assert folder is not None
                        report = grade_package(grader, exercise, folder, scratch, seed=seed)
                    else:
                        script = scratch / f"{exercise.slug}.py"
                        script.write_text(code, encoding="utf-8")
                        runner.start(supervisor, exercise, script)
                        try:
                            report = grader.grade(exercise, script, seed=seed)
                        finally:
                            runner.stop(supervisor, exercise)
                            for setup in exercise.setup:
                                supervisor.stop(setup).result()
                    if report.passed == should_pass:
                        right += 1
                    else:
                        wrong_seeds.append(seed)
                        text = "\n".join([report.problem, *(r.line() for r in report.results)])
                        print(f"WRONG {exercise.slug}/{name} seed {seed}:\n{text}", flush=True)
                key = f"{exercise.slug}/{name}"
                figures[key] = {
                    "right": right,
                    "runs": runs,
                    "should_pass": should_pass,
                    "wrong_seeds": wrong_seeds,
                }
                print(f"{key}: {right}/{runs} graded right", flush=True)
    finally:
        supervisor.shutdown()
        runtime.shutdown()
        for burner in burners:
            try:
                os.killpg(burner.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            burner.wait()
    total = sum(int(f["runs"]) for f in figures.values())  # type: ignore[call-overload]
    good = sum(int(f["right"]) for f in figures.values())  # type: ignore[call-overload]
    took = time.monotonic() - started
    load_text = f"load average {min(loads):.1f}-{max(loads):.1f}" if loads else ""
    print(f"all: {good}/{total} graded right in {took:.0f} s; {load_text}", flush=True)
    if args.out:
        summary = {
            "burn": args.burn,
            "load_cmd": args.load_cmd,
            "seconds": round(took),
            "load_average_1min": {
                "min": min(loads, default=0.0),
                "median": sorted(loads)[len(loads) // 2] if loads else 0.0,
                "max": max(loads, default=0.0),
            },
            "figures": figures,
        }
        args.out.write_text(json.dumps(summary, indent=1))
    return 0 if good == total else 1


if __name__ == "__main__":
    raise SystemExit(main())
