"""Every graded attempt is kept as a bag (app/exercises/attempts.py).

A real grading of the services exercise, recorded: the bag is read by the
independent ``mcap`` reader and holds the learner node's own log lines, its
name and metadata carry the seed and the verdict. The store keeps the newest
attempts of an exercise and stays under its size; a folder that cannot be
written leaves the grading as it was, with the reason the attempt was not kept.
"""

from __future__ import annotations

import calendar
import json
from pathlib import Path

import pytest
import yaml

from app.exercises import runner
from app.exercises.attempt_folders import (
    attempt_heading,
    attempt_label,
    finished_name,
    graded_code,
    replay_of,
)
from app.exercises.attempts import AttemptStore, keep_graded_code, next_attempt_path
from app.exercises.grader import Grader
from app.exercises.report import Report
from tests.bags.readers import mcap_messages
from tests.conftest import fail_on_leftover_nodes
from tests.course_data import shared_exercises
from tests.exercises.grading_participant import grading_participant

SLUG = "multiply_service"
EXERCISE = shared_exercises().get(SLUG)


def _attempt(root: Path, slug: str, name: str, size: int = 10) -> Path:
    folder = root / slug / name
    folder.mkdir(parents=True)
    (folder / "bag_0.mcap").write_bytes(b"x" * size)
    return folder


def test_the_newest_attempts_of_an_exercise_stay(tmp_path):
    store = AttemptStore(tmp_path, keep=2)
    names = [
        "20261129-100000-seed1-fail",
        "20261129-100100-seed2-fail",
        "20261129-100200-seed3-pass",
    ]
    made = [_attempt(tmp_path, SLUG, name) for name in names]
    other = _attempt(tmp_path, "talker_rate", "20261129-090000-seed9-fail")
    store.prune(SLUG, made[-1])
    assert [p.name for p in store.attempts(SLUG)] == names[1:]
    assert other.exists()  # another exercise's attempts are counted apart


def test_two_gradings_within_one_second_get_two_folders(tmp_path):
    """CI: a quick exercise graded twice in one second lost the second attempt, whose
    final name was the first's (the first no longer had its .recording name)."""
    when = calendar.timegm((2026, 11, 30, 10, 7, 2, 0, 0, 0))
    folder = tmp_path / SLUG
    first = next_attempt_path(folder, when)
    assert first.name == "20261130-100702.recording"
    _attempt(tmp_path, SLUG, finished_name(first.name, 7, "fail"))
    second = next_attempt_path(folder, when)
    assert second.name == "20261130-100702-2.recording"
    _attempt(tmp_path, SLUG, second.name)  # still recording
    assert next_attempt_path(folder, when).name == "20261130-100702-3.recording"
    assert next_attempt_path(folder, when + 1).name == "20261130-100703.recording"


def test_the_oldest_attempts_of_all_exercises_go_first_over_the_size_cap(tmp_path):
    store = AttemptStore(tmp_path, keep=10, cap_bytes=250)
    oldest = _attempt(tmp_path, "talker_rate", "20261129-090000-seed9-fail", size=100)
    middle = _attempt(tmp_path, SLUG, "20261129-100000-seed1-fail", size=100)
    newest = _attempt(tmp_path, SLUG, "20261129-110000-seed2-fail", size=100)
    store.prune(SLUG, newest)
    assert not oldest.exists() and middle.exists() and newest.exists()
    # One attempt alone over the cap is not kept either.
    huge = _attempt(tmp_path, SLUG, "20261129-120000-seed3-fail", size=1000)
    store.prune(SLUG, huge)
    assert not huge.exists() and not middle.exists() and not newest.exists()


def test_attempts_are_listed_by_time_verdict_and_seed_and_a_damaged_one_says_so(tmp_path):
    kept = _attempt(tmp_path, SLUG, "20261129-101500-seed4242-fail")
    assert attempt_label(kept) == "2026-11-29 10:15:00 UTC · fail · seed 4242"
    again = _attempt(tmp_path, SLUG, "20261129-101500-2-seed5-pass")
    assert attempt_label(again) == "2026-11-29 10:15:00 UTC · pass · seed 5"
    killed = _attempt(tmp_path, SLUG, "20261129-101600.recording")
    assert "damaged" in attempt_label(killed) and "reindex" in attempt_label(killed)
    assert attempt_heading(killed) == ""  # no metadata.yaml: nothing to read, no crash
    (kept / "metadata.yaml").write_text("rosbag2_bagfile_information: [", encoding="utf-8")
    assert attempt_heading(kept) == ""


def test_the_graded_file_is_kept_with_its_attempt_and_the_replay_names_it(tmp_path):
    learner = tmp_path / "code" / f"{SLUG}.py"
    learner.parent.mkdir()
    learner.write_text("print('as graded')\n", encoding="utf-8")
    kept = _attempt(tmp_path, SLUG, "20261129-101500-seed4242-fail")
    assert keep_graded_code(learner, kept) == ""
    learner.write_text("print('changed since')\n", encoding="utf-8")
    assert graded_code(kept).read_text(encoding="utf-8") == "print('as graded')\n"
    assert replay_of(kept) == (
        f"ros2-classroom exercise check {SLUG} {kept / 'graded.py'} --seed 4242"
    )


def test_a_package_is_kept_whole_without_its_build_products(tmp_path):
    package = tmp_path / "ws" / "src" / "py_doubler"
    node = package / "py_doubler" / "doubler.py"
    node.parent.mkdir(parents=True)
    node.write_text("# node\n", encoding="utf-8")
    (package / "package.xml").write_text("<package/>", encoding="utf-8")
    (package / "setup.py").write_text("# setup\n", encoding="utf-8")
    (package / "py_doubler" / "__pycache__").mkdir()
    (package / "py_doubler" / "__pycache__" / "doubler.pyc").write_bytes(b"\0")
    kept = _attempt(tmp_path, "package_doubler", "20261129-101500-seed7-pass")
    assert keep_graded_code(node, kept, package=True) == ""
    copy = graded_code(kept)
    assert copy == kept / "graded" / "py_doubler"
    assert sorted(str(p.relative_to(copy)) for p in copy.rglob("*") if p.is_file()) == [
        "package.xml",
        "py_doubler/doubler.py",
        "setup.py",
    ]
    assert replay_of(kept).endswith(f"{copy} --seed 7")  # `exercise check` takes the folder
    lonely = tmp_path / "lonely.py"
    lonely.write_text("", encoding="utf-8")
    assert "no package.xml" in keep_graded_code(lonely, kept, package=True)


def test_code_that_cannot_be_kept_says_why_and_never_raises(tmp_path):
    learner = tmp_path / f"{SLUG}.py"
    learner.write_text("x = 1\n", encoding="utf-8")
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("a file where the attempt folder should be", encoding="utf-8")
    assert keep_graded_code(learner, blocker) != ""
    assert keep_graded_code(tmp_path / "gone.py", tmp_path) != ""
    big = tmp_path / "big.py"
    big.write_bytes(b"#" * (2 * 1024 * 1024))
    assert "larger than" in keep_graded_code(big, _attempt(tmp_path, SLUG, "x"))
    assert graded_code(tmp_path / SLUG / "x") is None and replay_of(tmp_path / SLUG / "x") == ""


@pytest.fixture(scope="module")
def grading(tmp_path_factory):
    with grading_participant("attempt_test_grader", domain_id=78) as (node, supervisor):
        yield node, supervisor, tmp_path_factory.mktemp("code")


def _grade(grading, store: AttemptStore, code: str, seed: int) -> Report:
    node, supervisor, scratch = grading
    script = scratch / f"{SLUG}.py"
    script.write_text(code, encoding="utf-8")
    runner.start(supervisor, EXERCISE, script)
    try:
        return Grader(node, supervisor, store).grade(EXERCISE, script, seed=seed)
    finally:
        runner.stop(supervisor, EXERCISE)
        fail_on_leftover_nodes("this case")


@pytest.mark.ros
def test_a_graded_attempt_is_a_bag_with_the_learners_log_seed_and_verdict(grading, tmp_path):
    store = AttemptStore(tmp_path / "attempts")
    mistake = next(m for m in EXERCISE.mistakes if m.path.stem == "adds")
    report = _grade(grading, store, mistake.path.read_text(encoding="utf-8"), seed=4242)
    assert not report.passed and not report.problem, report.summary()
    assert report.attempt and not report.attempt_note, report.attempt_note
    bag = Path(report.attempt)
    assert bag.parent == tmp_path / "attempts" / SLUG
    assert bag.name.endswith("-seed4242-fail")
    # The code it graded is kept beside it, and the replay grades that copy.
    kept = graded_code(bag)
    assert kept == bag / "graded.py"
    assert kept.read_text(encoding="utf-8") == mistake.path.read_text(encoding="utf-8")
    assert replay_of(bag).endswith(f"{kept} --seed 4242")

    meta = yaml.safe_load((bag / "metadata.yaml").read_text(encoding="utf-8"))
    custom = meta["rosbag2_bagfile_information"]["custom_data"]
    assert custom["classroom.exercise"] == SLUG
    assert custom["classroom.seed"] == "4242"
    assert custom["classroom.verdict"] == "fail"
    results = json.loads(custom["classroom.results"])
    assert [r["detail"] for r in results] == [r.detail for r in report.results]
    # What Watch this attempt shows first: the verdict and each line, read from the bag.
    heading = attempt_heading(bag)
    assert report.summary() in heading and report.failures()[0].detail in heading

    # The independent reader: the learner node's own lines, as it answered the probes.
    messages = mcap_messages(bag)
    logged = [m.msg for topic, _t, m in messages if topic == "/rosout" and m.name == "multiplier"]
    assert logged, f"no log line of /multiplier in the attempt ({len(messages)} messages)"

    # A second attempt: a pass, beside the first.
    report = _grade(grading, store, EXERCISE.reference, seed=5)
    assert report.passed, report.summary()
    assert [p.name.split("-seed")[1] for p in store.attempts(SLUG)] == ["4242-fail", "5-pass"]


@pytest.mark.ros
def test_an_unwritable_attempts_folder_never_stops_the_grading(grading, tmp_path):
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("a file where the attempts folder should be", encoding="utf-8")
    report = _grade(grading, AttemptStore(blocker / "attempts"), EXERCISE.reference, seed=6)
    assert report.passed, report.summary()
    assert not report.attempt
    assert report.attempt_note.startswith("attempt not kept: cannot record into")
