"""Grade references and mistakes many times over, on a loaded machine: are grades stable?

Run through the private network namespace:
``.venv/bin/python tests/run.py --script tests/exercises/repeat_grading.py -- --runs 5``.
Every grading draws a fresh seed (printed with any wrong grade, to replay it).
``--burn N`` keeps N busy-looping processes running meanwhile (a second test
suite's worth of load on 2 cores); they are ended by their pids at the end.
Writes a JSON summary to ``--out``.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from app.exercises import runner
from app.exercises.model import load_exercises

BURN = "import time\nwhile True:\n    sum(i * i for i in range(10000)); time.sleep(0.001)\n"


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--slugs", nargs="*", default=None)
    parser.add_argument("--which", choices=("reference", "mistakes", "all"), default="all")
    parser.add_argument("--burn", type=int, default=1)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()

    from app.dds import configure_dds_env
    from app.exercises.grader import Grader
    from app.exercises.package_grading import grade_package
    from app.ros.runtime import RosRuntime
    from app.supervisor import Supervisor

    configure_dds_env(os.environ, domain_id=60 + os.getpid() % 30, network=False)
    book = load_exercises()
    exercises = [e for e in book.exercises if args.slugs is None or e.slug in args.slugs]
    burners = [subprocess.Popen([sys.executable, "-c", BURN]) for _ in range(args.burn)]
    runtime = RosRuntime("repeat_grader")
    supervisor = Supervisor(os.environ)
    grader = Grader(runtime.node, supervisor)
    scratch = Path(tempfile.mkdtemp(prefix="repeat_grading_"))
    figures: dict[str, dict[str, object]] = {}
    started = time.monotonic()
    try:
        for exercise in exercises:
            cases = []
            if args.which in ("reference", "all"):
                cases.append(("reference", exercise.reference, True, exercise.reference_dir))
            if args.which in ("mistakes", "all"):
                cases += [
                    (m.path.parent.name, "", False, m.path)
                    if exercise.is_package
                    else (m.path.stem, m.path.read_text(), False, None)
                    for m in exercise.mistakes
                ]
            for name, code, should_pass, folder in cases:
                right, wrong_seeds = 0, []
                for _ in range(args.runs):
                    seed = random.SystemRandom().randrange(1, 1_000_000)
                    if exercise.is_package:  # built with colcon, then run or launched
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
                figures[key] = {"right": right, "runs": args.runs, "wrong_seeds": wrong_seeds}
                print(f"{key}: {right}/{args.runs} graded right", flush=True)
    finally:
        supervisor.shutdown()
        runtime.shutdown()
        for burner in burners:
            burner.kill()
            burner.wait()
    total = sum(int(f["runs"]) for f in figures.values())  # type: ignore[call-overload]
    good = sum(int(f["right"]) for f in figures.values())  # type: ignore[call-overload]
    print(f"all: {good}/{total} graded right in {time.monotonic() - started:.0f} s", flush=True)
    if args.out:
        args.out.write_text(json.dumps({"burn": args.burn, "figures": figures}, indent=1))
    return 0 if good == total else 1


if __name__ == "__main__":
    raise SystemExit(main())
