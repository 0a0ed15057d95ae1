"""A grading replays exactly from its seed: `exercise check SLUG FILE --seed N`, end to end.

The same file graded twice with the same seed is fed the same hidden inputs and gets the
same verdicts; another seed draws other inputs. Run as a teacher runs it, through the CLI.
"""

from __future__ import annotations

import re
from pathlib import Path

from tests.conftest import run_cli
from tests.course_data import shared_exercises

EXERCISE = shared_exercises().get("running_sum")
MISTAKE = next(m for m in EXERCISE.mistakes if m.path.stem == "resets_total")
FED = re.compile(r"published (\[[-0-9, ]+\])")


def _check(ros_env, file: Path, seed: int) -> tuple[int, list[str], str]:
    """(exit code, the verdict lines, the inputs the grader published).

    The grading is recorded into the bags folder of this test, and the output names it.
    """
    bags = file.parent / "bags"
    env = {**ros_env, "ROS2_CLASSROOM_BAGS": str(bags)}
    done = run_cli(
        "exercise", "check", EXERCISE.slug, str(file), "--seed", str(seed), env=env, timeout=120
    )
    recorded = re.search(r"^recorded: (\S+)$", done.stdout, re.MULTILINE)
    assert recorded, f"the attempt was not kept:\n{done.stdout}"
    kept = Path(recorded.group(1))
    assert kept.parent == bags / "attempts" / EXERCISE.slug and kept.name.endswith(
        f"-seed{seed}-{'pass' if done.returncode == 0 else 'fail'}"
    ), kept
    assert (kept / "metadata.yaml").is_file()
    verdicts = [line for line in done.stdout.splitlines() if line.startswith(("PASS", "FAIL"))]
    fed = FED.search(done.stdout)
    assert fed, f"no inputs in the output:\n{done.stdout}\n{done.stderr[-1500:]}"
    assert f"seed {seed}" in done.stdout and f"--seed {seed}" in done.stdout, done.stdout
    return done.returncode, verdicts, fed.group(1)


def test_the_same_seed_replays_inputs_and_verdicts_and_another_seed_draws_others(ros_env, tmp_path):
    wrong = tmp_path / "resets_total.py"
    wrong.write_text(MISTAKE.path.read_text(encoding="utf-8"))
    right = tmp_path / "running_sum.py"
    right.write_text(EXERCISE.reference)

    first = _check(ros_env, wrong, 4242)
    again = _check(ros_env, wrong, 4242)
    assert first[0] == again[0] == 1
    assert first == again, f"the same seed graded differently:\n{first}\n{again}"
    assert any(MISTAKE.reason in line for line in first[1]), first[1]

    code, _verdicts, fed = _check(ros_env, right, 4242)
    assert code == 0 and fed == first[2], "the reference was fed other inputs for the same seed"

    other = _check(ros_env, wrong, 4243)
    assert other[2] != first[2], "another seed fed the same inputs"
