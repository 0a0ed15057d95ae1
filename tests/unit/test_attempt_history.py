"""A learner's graded attempts on their way to the gradebook's history, and the page itself.

The attempts a dashboard keeps (folders named by time, seed and verdict, with
the grader's lines in ``metadata.yaml``) read back as plain data; the HTTP
progress report carries them, checked field by field; the hub keeps them per
learner; the history page shows each one with its seed, the command that
replays it, and what the LMS has.
"""

from __future__ import annotations

import html
import json
import re
import subprocess
import sys
from dataclasses import asdict, replace
from pathlib import Path

import pytest
import yaml

from app.exercises import attempt_folders
from app.exercises.attempt_folders import ResultLine, custom_data, finished_name, unfinished_names
from app.lti.gradebook import GradebookLine
from app.lti.history import Attempt, AttemptHistory, AttemptSource
from app.lti.pages import (
    attempts_page,
    class_grid,
    history_link,
    not_found_page,
    replay_command,
)
from app.teacher.attempt_files import AttemptReader, attempt_from_folder, exercise_folder
from app.teacher.http_report import ReportError, from_json, to_json
from app.teacher.record import MAX_HISTORY, MAX_REASON, GradedAttempt, LearnerRecord

SLUG = "wall_stop"


def keep_attempt(
    folder: Path,
    name: str,
    results: list[tuple[str, bool, str]] | None,
    summary: str = "",
) -> Path:
    """An attempt folder as app/exercises/attempts.py leaves it (``None``: no metadata)."""
    path = folder / name
    path.mkdir(parents=True)
    if results is not None:
        custom = {
            "classroom.exercise": SLUG,
            "classroom.summary": summary,
            "classroom.results": json.dumps(
                [{"name": n, "passed": p, "detail": d} for n, p, d in results]
            ),
        }
        meta = {"rosbag2_bagfile_information": {"version": 9, "custom_data": custom}}
        (path / "metadata.yaml").write_text(yaml.safe_dump(meta), encoding="utf-8")
    return path


def test_a_folder_named_and_filled_as_a_grading_does_reads_back_as_that_grading(
    tmp_path: Path,
) -> None:
    """The names and the metadata the dashboard writes (app/exercises/attempts.py calls
    these very functions) come back as the gradebook's attempt, second gradings too."""
    folder = exercise_folder(tmp_path, SLUG)
    when = 1795947600.0  # 2026-11-29 10:20:00 UTC
    results = [ResultLine("stop", True, "ok"), ResultLine("wall", False, "0.21 m\nof it")]
    names = iter(unfinished_names(when))
    (folder / next(names)).mkdir(parents=True)  # a grading still being recorded
    for seed, verdict in ((4242, "fail"), (None, "problem")):
        unfinished = folder / next(names)
        unfinished.mkdir()
        custom = custom_data(SLUG, seed, verdict, f"{verdict} summary", results)
        meta = {"rosbag2_bagfile_information": {"custom_data": {
            attempt_folders.CUSTOM_PREFIX + k: v for k, v in custom.items()}}}  # fmt: skip
        (unfinished / "metadata.yaml").write_text(yaml.safe_dump(meta), encoding="utf-8")
        unfinished.rename(folder / finished_name(unfinished.name, seed, verdict))
    assert sorted(p.name for p in folder.iterdir()) == [
        "20261129-102000-2-seed4242-fail",
        "20261129-102000-3-problem",
        "20261129-102000.recording",
    ]
    problem, failed = AttemptReader().newest(folder)  # the later of one second first
    assert (failed.at, failed.verdict, failed.seed, failed.passed, failed.total) == (
        when, "fail", 4242, 1, 2)  # fmt: skip
    assert failed.failed == ("wall: 0.21 m of it",) and failed.summary == "fail summary"
    assert (problem.verdict, problem.seed, problem.summary) == ("problem", 0, "problem summary")
    assert custom["verdict"] == "not graded"  # as `ros2 bag info` shows a problem
    # The first grading of a second has no -n: it still sorts before the second one.
    one_second = ["20261129-102000-2-problem", "20261129-102000-seed9-fail"]
    assert sorted(one_second, key=attempt_folders.age_order) == one_second[::-1]


def test_reading_attempts_needs_no_ros() -> None:
    """A hub's teacher service reads them where rclpy is not installed."""
    code = (
        "import sys, app.teacher.attempt_files, app.exercises.attempt_folders; "
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('rclpy', 'rosidl_parser')"
        " or m.startswith('app.exercises.') and m != 'app.exercises.attempt_folders'))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_the_replay_commands_of_the_cli_and_the_gradebook_agree(tmp_path: Path) -> None:
    kept = tmp_path / SLUG / "20261129-101500-seed4242-fail"
    (kept / "graded.py").parent.mkdir(parents=True)
    (kept / "graded.py").write_text("print('the code that was graded')")
    command = attempt_folders.replay_of(kept)
    assert command == replay_command(SLUG, 4242, str(kept / "graded.py"))
    assert command.endswith(f"{kept / 'graded.py'} --seed 4242")
    package = tmp_path / SLUG / "20261129-101600-seed5-pass"
    (package / "graded" / "py_doubler").mkdir(parents=True)
    assert attempt_folders.graded_code(package) == package / "graded" / "py_doubler"
    assert attempt_folders.replay_of(tmp_path / SLUG / "20261129-101700-seed6-fail") == ""
    spaced = tmp_path / "a b" / SLUG / "20261129-101500-seed1-fail"
    spaced.mkdir(parents=True)
    (spaced / "graded.py").write_text("")
    assert f"'{spaced / 'graded.py'}'" in attempt_folders.replay_of(spaced)  # quoted


def test_kept_attempts_read_back_newest_first_with_seed_verdict_and_failed_checks(
    tmp_path: Path,
) -> None:
    folder = exercise_folder(tmp_path / "bags" / "learner1", SLUG)
    failing = keep_attempt(
        folder,
        "20261129-101500-seed4242-fail",
        [
            ("node_running /wall_stop", True, "running"),
            ("stop before the wall", False, "came within 0.21 m of the wall\n(bound 0.35 m)"),
        ],
        summary="1 of 2 checks passed: not yet. Inputs drawn with seed 4242.",
    )
    passed = keep_attempt(folder, "20261129-102000-seed77-pass", [("stop", True, "ok")])
    keep_attempt(folder, "20261129-101000-problem", [], summary="Not graded: not running")
    keep_attempt(folder, "20261129-102500.recording", None)  # being recorded: not yet
    keep_attempt(folder, "20261129-101400-seed5-fail", None)  # damaged: its name still tells
    (folder / "notes.txt").write_text("not an attempt")

    found = AttemptReader().newest(folder)
    assert [(a.verdict, a.seed) for a in found] == [
        ("pass", 77),
        ("fail", 4242),
        ("fail", 5),
        ("problem", 0),
    ]
    newest, failed, damaged, problem = found
    assert newest.at == 1795947600.0  # 2026-11-29 10:20:00 UTC
    assert (newest.passed, newest.total, newest.failed) == (1, 1, ())
    assert (failed.passed, failed.total) == (1, 2)
    assert failed.failed == ("stop before the wall: came within 0.21 m of the wall (bound 0.35 m)",)
    assert "seed 4242" in failed.summary
    assert (damaged.total, damaged.failed) == (0, ())
    assert problem.summary == "Not graded: not running"
    # The dashboard's own reader agrees on what the folder says.
    assert attempt_folders.attempt_label(passed).endswith("pass · seed 77")
    assert "came within 0.21 m of the wall" in attempt_folders.attempt_heading(failing)
    assert AttemptReader().newest(folder, limit=2) == found[:2]
    assert AttemptReader().newest(tmp_path / "nowhere") == ()


def test_a_long_reason_is_clipped_and_the_reader_forgets_pruned_attempts(tmp_path: Path) -> None:
    folder = tmp_path / SLUG
    keep_attempt(folder, "20261129-101500-seed1-fail", [("probe", False, "x" * 1000)])
    reader = AttemptReader()
    [attempt] = reader.newest(folder)
    assert len(attempt.failed[0]) == MAX_REASON and attempt.failed[0].endswith("…")
    for path in folder.iterdir():  # the dashboard pruned it
        for inner in path.iterdir():
            inner.unlink()
        path.rmdir()
    assert reader.newest(folder) == ()
    assert attempt_from_folder(tmp_path / "not-an-attempt") is None


# The HTTP report ------------------------------------------------------------------------

RECORD = LearnerRecord(
    site="hub",
    learner="lti-abc",
    exercise=SLUG,
    exercise_history=(
        GradedAttempt(1795947600.0, "pass", 77, 2, 2, (), "2 of 2 checks passed: passed."),
        GradedAttempt(1795947300.0, "fail", 4242, 1, 2, ("stop: too close",), "1 of 2"),
    ),
)


def test_the_history_survives_the_report() -> None:
    assert from_json(to_json(RECORD), received_at=5.0) == replace(RECORD, received_at=5.0)


def _with_history(*attempts: object) -> bytes:
    data = json.loads(to_json(RECORD))
    data["exercise_history"] = list(attempts)
    return json.dumps(data).encode()


GOOD = {"at": 1.0, "verdict": "fail", "seed": 3, "passed": 0, "total": 1, "failed": ["a: b"]}


@pytest.mark.parametrize(
    ("attempt", "reason"),
    [
        ("fail", "must be an object"),
        ({**GOOD, "code": "import os"}, "must be an object"),
        ({k: v for k, v in GOOD.items() if k != "at"}, "must be an object"),
        ({**GOOD, "at": -1}, "time in seconds"),
        ({**GOOD, "verdict": "<b>"}, "verdict of pass, fail, problem"),
        ({**GOOD, "seed": True}, "seed must be a whole number"),
        ({**GOOD, "total": 2**32}, "total must be a whole number"),
        ({**GOOD, "failed": "a: b"}, "failed must be a list of strings"),
        ({**GOOD, "summary": 3}, "summary must be a string"),
        ({**GOOD, "graded_file": 3}, "graded_file must be a path"),
        ({**GOOD, "graded_file": "/x\n; rm -rf ~"}, "graded_file must be a path"),
        ({**GOOD, "graded_file": "/x" * 200}, "graded_file must be a path"),
    ],
)
def test_a_bad_attempt_in_a_report_gets_its_reason(attempt: object, reason: str) -> None:
    with pytest.raises(ReportError, match=reason):
        from_json(_with_history(attempt), received_at=0.0)


def test_a_report_keeps_at_most_the_newest_attempts_and_clips_their_texts() -> None:
    many = [{**GOOD, "at": float(i), "failed": ["f" * 200] * 10} for i in range(12)]
    record = from_json(_with_history(*many), received_at=0.0)
    assert len(record.exercise_history) == MAX_HISTORY
    assert all(len(a.failed) == 8 for a in record.exercise_history)
    assert all(len(f) == MAX_REASON for a in record.exercise_history for f in a.failed)
    history = from_json(_with_history(), received_at=0.0).exercise_history
    assert history == ()


# The hub's keeping ------------------------------------------------------------------------


def attempt(at: float, verdict: str = "fail", seed: int = 1) -> Attempt:
    return Attempt(at, verdict, seed, 0, 1, ("stop: too close",), "")


def test_the_hub_keeps_each_new_attempt_once_the_newest_first_across_restarts(
    tmp_path: Path,
) -> None:
    history = AttemptHistory(tmp_path, keep=3)
    assert history.add("lti-abc", SLUG, [attempt(2.0), attempt(1.0)]) == 2
    assert history.add("lti-abc", SLUG, [attempt(3.0, "pass", 9), attempt(2.0)]) == 1  # 2.0 known
    assert history.add("lti-abc", SLUG, [attempt(4.0), attempt(3.0, "pass", 9)]) == 1
    assert [a.at for a in history.of("lti-abc", SLUG)] == [4.0, 3.0, 2.0]  # the newest 3
    again = AttemptHistory(tmp_path, keep=3)
    assert again.of("lti-abc", SLUG) == history.of("lti-abc", SLUG)
    assert again.of("lti-abc", "other_exercise") == ()
    # Names that could leave the folder never reach a path.
    assert history.add("../etc", SLUG, [attempt(1.0)]) == 0
    assert history.add("lti-abc", "../../x", [attempt(1.0)]) == 0
    assert sorted(p.name for p in (tmp_path / "attempts").iterdir()) == ["lti-abc.json"]


def test_an_unreadable_history_file_starts_afresh(tmp_path: Path) -> None:
    (tmp_path / "attempts").mkdir()
    (tmp_path / "attempts" / "lti-abc.json").write_text("{not json")
    history = AttemptHistory(tmp_path)
    assert history.of("lti-abc", SLUG) == ()
    assert history.add("lti-abc", SLUG, [attempt(1.0)]) == 1
    assert AttemptHistory(tmp_path).of("lti-abc", SLUG) == (attempt(1.0),)


# The page -----------------------------------------------------------------------------------


def line(state: str, **changes: object) -> GradebookLine:
    base = GradebookLine(
        learner="lti-abc",
        lms_name="Ada <Lovelace>",
        activity="Stop at the wall",
        link="Week 3 in Robotics 101",
        lineitem="https://lms.example/lineitems/7",
        state=state,  # type: ignore[arg-type]
        score="5 of 5",
        queued_at="2026-11-29T10:20:01+00:00",
        sent_at=1795947602.0 if state == "sent" else None,
        lms_answer="",
        attempts=1,
        next_try=None,
        launched_at=1795947000.0,
        comment="Exercise wall_stop passed ... seed 77",
        kind="exercise",
        slug=SLUG,
    )
    return replace(base, **changes)  # type: ignore[arg-type]


SOURCE = AttemptSource(
    (
        Attempt(1795947600.0, "pass", 77, 2, 2, (), "2 of 2 checks passed: passed."),
        Attempt(1795947300.0, "fail", 4242, 1, 2, ("stop before the wall: <0.21 m>",), ""),
        Attempt(1795947240.0, "problem", 0, 0, 0, (), "Not graded: your program is not running"),
    ),
    where="As the learner's dashboard reported them.",
    replay="the teacher service runs no ROS 2 graph",
)


def text(page: str) -> str:
    return html.unescape(re.sub(r"<[^>]+>", " ", page))


def attempt_rows(page: str) -> list[str]:
    body = page.split('<table id="attempts"', 1)[1].split("<tbody>", 1)[1].split("</tbody>")[0]
    return [text(row) for row in re.findall(r"<tr[^>]*>(.*?)</tr>", body, re.S)]


def test_the_history_shows_each_attempt_with_its_seed_and_the_command_that_replays_it() -> None:
    page = attempts_page(
        [line("sent")], learner="lti-abc", kind="exercise", slug=SLUG, source=SOURCE, now=0.0
    )
    assert "<Lovelace>" not in page and "Ada &lt;Lovelace&gt;" in page  # escaped
    passed, failed, problem = attempt_rows(page)
    assert "2026-11-29 10:20:00 UTC" in passed and "✓ passed" in passed and "2 of 2" in passed
    assert f"ros2-classroom exercise check {SLUG} FILE --seed 77" in passed
    assert "✗ failed" in failed and "1 of 2" in failed and "4242" in failed
    assert "stop before the wall: <0.21 m>" in failed
    assert f"exercise check {SLUG} FILE --seed 4242" in failed
    assert "⚠ not graded" in problem and "your program is not running" in problem
    assert "nothing to replay" in problem and "--seed" not in problem
    assert 'data-copy="ros2-classroom exercise check wall_stop FILE --seed 4242"' in page
    words = text(page)
    assert "3 shown: 1 passed, 1 failed, 1 not graded" in words
    assert "There is no replay button here: the teacher service runs no ROS 2 graph" in words
    assert "<button" in page and "replay</button>" not in page.lower()
    # What the LMS has: the line's state, its answer, and what the score told it.
    lms = text(page.split('<table id="lms"', 1)[1].split("</table>", 1)[0])
    assert "✓ sent" in lms and "5 of 5" in lms and "accepted" in lms
    assert "Exercise wall_stop passed ... seed 77" in words
    assert 'href="../gradebook"' in page


def test_the_lms_state_shows_a_waiting_score_and_a_refused_one_with_the_lms_answer() -> None:
    waiting = line("waiting", lms_answer="HTTP 503: maintenance", next_try=60.0, attempts=2)
    refused = line("refused", lms_answer="HTTP 403: not enrolled", link="Week 3 in Robotics 102")
    page = attempts_page(
        [waiting, refused], learner="lti-abc", kind="exercise", slug=SLUG, source=SOURCE, now=0.0
    )
    lms = text(page.split('<table id="lms"', 1)[1].split("</table>", 1)[0])
    assert (
        "… waiting" in lms and "HTTP 503: maintenance" in lms and "in 60 s (after 2 tries)" in lms
    )
    assert "✗ refused" in lms and "HTTP 403: not enrolled" in lms and "Robotics 102" in lms


def test_a_classroom_names_the_code_file_and_where_the_recordings_are() -> None:
    source = replace(
        SOURCE,
        code_file="/srv/p/learner1/learner1.code/wall_stop.py",
        recordings="Each of these gradings is recorded in /srv/p/bags/learner1.",
    )
    page = attempts_page(
        [line("sent", seat="learner1")],
        learner="lti-abc",
        kind="exercise",
        slug=SLUG,
        source=source,
        now=0.0,
    )
    words = text(page)
    assert f"exercise check {SLUG} /srv/p/learner1/learner1.code/wall_stop.py --seed 77" in words
    assert "dashboard learner1" in words and "recorded in /srv/p/bags/learner1" in words


def test_no_attempt_yet_and_a_lesson_say_so() -> None:
    empty = replace(SOURCE, attempts=())
    page = attempts_page(
        [line("not done")], learner="lti-abc", kind="exercise", slug=SLUG, source=empty, now=0.0
    )
    assert "No graded attempt of wall_stop is known here yet." in text(page)
    assert 'id="attempts"' not in page
    lesson = attempts_page(
        [line("waiting", kind="lesson", slug="05_topics")],
        learner="lti-abc",
        kind="lesson",
        slug="05_topics",
        source=None,
        now=0.0,
    )
    assert "A lesson has no graded attempts" in text(lesson) and "--seed" not in lesson


def test_each_cell_of_the_grid_links_its_learners_history_of_its_activity() -> None:
    lesson = line("not done", kind="lesson", slug="05_topics", activity="Lesson 5")
    grid = class_grid([line("sent"), lesson])
    links = [html.unescape(h) for h in re.findall(r'href="(gradebook/attempts[^"]+)"', grid)]
    assert links == [
        "gradebook/attempts?learner=lti-abc&activity=lesson%3A05_topics",
        f"gradebook/attempts?learner=lti-abc&activity=exercise%3A{SLUG}",
    ]
    assert history_link("lti-a&b", "exercise", SLUG) == (
        f"gradebook/attempts?learner=lti-a%26b&activity=exercise%3A{SLUG}"
    )


def test_a_bad_address_gets_a_page_that_says_why() -> None:
    page = not_found_page("no learner '<x>' has opened anything from the LMS here")
    assert "&lt;x&gt;" in page and "<x>" not in page and "Back to the gradebook" in page


def test_the_attempt_types_share_their_fields() -> None:
    """The teacher's record carries them, the LTI layer shows them: one field list."""
    graded = RECORD.exercise_history[0]
    assert Attempt(**asdict(graded)).key == (graded.at, graded.verdict, graded.seed)


def test_the_teacher_page_names_the_replay_of_the_newest_attempt_on_its_kept_code(
    tmp_path: Path,
) -> None:
    from app.teacher.page import attempt_text

    kept = keep_attempt(tmp_path / SLUG, "20261129-101500-seed4242-fail", [("stop", False, "x")])
    assert "exercise check" not in attempt_text(kept)  # no code kept: nothing to name
    (kept / "graded.py").write_text("print('graded')")
    assert f"`ros2-classroom exercise check {SLUG} {kept / 'graded.py'} --seed 4242`" in (
        attempt_text(kept)
    )


def test_an_attempt_that_kept_its_code_is_replayed_on_that_copy(tmp_path: Path) -> None:
    folder = exercise_folder(tmp_path / "bags", SLUG)
    kept = keep_attempt(folder, "20261129-102000-seed77-pass", [("stop", True, "ok")])
    (kept / "graded.py").write_text("print('graded')")
    keep_attempt(folder, "20261129-101500-seed4242-fail", [("stop", False, "too close")])
    newest, older = AttemptReader().newest(folder)
    assert (newest.graded_file, older.graded_file) == (str(kept / "graded.py"), "")
    # The report carries it to a hub, the page names it; the older one names the code as now.
    record = replace(RECORD, exercise_history=(newest, older))
    carried = from_json(to_json(record), received_at=0.0).exercise_history
    source = replace(
        SOURCE, attempts=tuple(Attempt(**asdict(a)) for a in carried), code_file="/code/w.py"
    )
    page = attempts_page(
        [line("sent")], learner="lti-abc", kind="exercise", slug=SLUG, source=source, now=0.0
    )
    passed, failed = attempt_rows(page)
    assert f"exercise check {SLUG} {kept / 'graded.py'} --seed 77" in passed
    assert f"exercise check {SLUG} /code/w.py --seed 4242" in failed
    assert "gives its verdict again" in text(page)
