"""The teacher's table: the stuck rule, the rows, the CSV, and the message's bounds."""

from __future__ import annotations

import csv
import io
from dataclasses import replace

from app.teacher import wire
from app.teacher.record import (
    COLUMNS,
    MAX_CODE,
    LearnerRecord,
    StuckRule,
    checks_text,
    class_exercises,
    exercise_now,
    mistake_words,
    table,
    tally_exercises,
    text_table,
    to_csv,
)
from app.teacher.status import render

NOW = 1_800_000_000.0


def _learner(name: str = "learner1", **fields) -> LearnerRecord:
    base = dict(
        site="A",
        learner=name,
        domain_id=10,
        lesson_id="05_topics",
        unit=3,
        lesson_title="Topics",
        step=2,
        steps=6,
        step_title="A publisher",
        check_states=("pass", "fail"),
        check_reasons=("ok", "no publisher on /chatter"),
        last_activity=NOW - 5,
        last_progress=NOW - 5,
        received_at=NOW - 1,
    )
    base.update(fields)
    return LearnerRecord(**base)


def test_stuck_after_a_quiet_spell_with_a_failing_check():
    rule = StuckRule(no_progress_sec=120, failed_checks=3)
    assert rule.reason(_learner(last_progress=NOW - 60), NOW) == ""
    assert "no progress for 2 min" in rule.reason(_learner(last_progress=NOW - 150), NOW)
    # A quiet learner whose checks all pass (or wait) is reading, not stuck.
    passing = _learner(last_progress=NOW - 900, check_states=("pass", "waiting"))
    assert rule.reason(passing, NOW) == ""


def test_stuck_when_the_same_exercise_keeps_failing():
    rule = StuckRule(no_progress_sec=600, failed_checks=3)
    trying = _learner(exercise="counter_publisher", exercise_failed_here=2, check_states=())
    assert rule.reason(trying, NOW) == ""
    failing = _learner(exercise="counter_publisher", exercise_failed_here=3, check_states=())
    assert rule.reason(failing, NOW) == "counter_publisher failed 3 times"
    passed = _learner(
        exercise="counter_publisher",
        exercise_failed_here=5,
        exercise_passed_here=True,
        check_states=(),
    )
    assert rule.reason(passed, NOW) == ""


def test_rows_are_sorted_naturally_and_say_everything():
    records = [_learner("learner10"), _learner("learner2", nodes_running=("talker",))]
    rows = table(records, StuckRule(), NOW)
    assert [row[0] for row in rows] == ["learner2", "learner10"]
    row = dict(zip(COLUMNS, rows[0], strict=True))
    assert row["where"] == "A · domain 10"
    assert row["unit · step"] == "3 · 2/6"
    assert row["checks"] == "✓✗ 1/2"
    assert row["nodes"] == "talker"
    assert row["exercise now"] == "–"
    assert row["last activity"] == "5 s ago"
    assert row["stuck"] == ""


def test_a_silent_dashboard_shows_as_offline():
    rows = table([_learner(received_at=NOW - 95)], StuckRule(), NOW)
    assert "offline" in rows[0][COLUMNS.index("last activity")]


def test_csv_has_one_row_per_learner_with_raw_values():
    records = [
        _learner("learner1", exercise="heartbeat_logger", exercise_attempts=4),
        _learner("learner2", site="B, second room", last_progress=NOW - 4000),
    ]
    parsed = list(csv.DictReader(io.StringIO(to_csv(records, StuckRule(), NOW))))
    assert [r["learner"] for r in parsed] == ["learner1", "learner2"]
    assert parsed[0]["exercise"] == "heartbeat_logger" and parsed[0]["exercise_attempts"] == "4"
    assert parsed[1]["site"] == "B, second room"  # quoted, not split
    assert parsed[1]["checks"] == "pass fail"
    assert parsed[1]["stuck"].startswith("no progress for")
    assert parsed[0]["last_activity"].endswith("Z")


def test_status_prints_the_same_rows_as_a_text_table():
    rows = table([_learner("learner1"), _learner("learner2")], StuckRule(), NOW)
    printed = render({"columns": list(COLUMNS), "rows": rows})
    lines = printed.splitlines()
    assert lines[0].split()[:2] == ["learner", "where"]
    assert lines[2].startswith("learner1  A · domain 10")
    assert printed.endswith("2 learners.")
    assert render({"columns": list(COLUMNS), "rows": []}) == "No learner has reported yet."
    assert text_table([], ("a", "bb")).splitlines() == ["a  bb", "-  --"]


def test_checks_text_without_checks():
    assert checks_text(_learner(check_states=())) == "–"


def test_message_round_trip_clips_to_the_bounds():
    long_code = "x = 1\n" * 2000
    record = _learner(
        code_excerpt=long_code,
        lesson_title="T" * 500,
        check_states=("pass",) * 20,
        check_reasons=("r",) * 20,
        nodes_running=("talker", "listener"),
        exercise="wall_stop",
        exercise_mistake="front_is_index_zero",
        exercise_passed_seed=987654,
    )
    msg = wire.to_message(record)
    back = wire.from_message(msg, received_at=NOW)
    assert len(back.code_excerpt) == MAX_CODE and back.code_excerpt.endswith("…")
    assert len(back.lesson_title) == 120
    assert len(back.check_states) == 16 == len(back.check_reasons)
    assert back.nodes_running == ("talker", "listener")
    assert back.exercise_mistake == "front_is_index_zero"
    assert back.exercise_passed_seed == 987654
    long_name = "log of your node contains " + "'beat' " * 40  # a failed check's name
    clipped = wire.from_message(wire.to_message(_learner(exercise_mistake=long_name)))
    assert len(clipped.exercise_mistake) == 120 and clipped.exercise_mistake.endswith("…")
    assert abs(back.last_activity - record.last_activity) < 1e-3
    assert back.key == "A/learner1"
    assert wire.node_name_for("host-1.lan", "learner1") == "classroom_learner_host_1_lan_learner1"


def test_the_learner_detail_is_read_only_text_that_cannot_break_out():
    from app.teacher.page import learner_detail, markdown_table

    code = 'print("```")\nx = 1  # | not a cell\n'
    shown = learner_detail(
        _learner(exercise="heartbeat_logger", code_excerpt=code, last_error="NameError: x")
    )
    assert "````python\n" + code + "\n````" in shown  # a longer fence than any inside
    assert shown.index("**Last error**") < shown.index("**Their code**")
    assert "no publisher on /chatter" in shown
    table_text = markdown_table([("a|b", "c")])
    assert "| a\\|b | c |" in table_text


def test_text_from_the_classroom_domain_is_shown_never_interpreted():
    from app.teacher.record import plain_markdown

    shown = plain_markdown("[win](http://evil) <img src=x>\n# big")
    assert shown == "\\[win\\]\\(http://evil\\) \\<img src=x\\> \\# big"


def _on(name: str, exercise: str = "wall_stop", **fields) -> LearnerRecord:
    return _learner(name, exercise=exercise, **fields)


def test_a_mistake_reads_as_plain_words_and_a_check_no_mistake_explains_as_failed():
    assert mistake_words("front_is_index_zero") == "front is index zero"
    assert mistake_words("adds") == "adds"
    assert mistake_words("stop before the wall") == "“stop before the wall” failed"
    assert mistake_words("") == ""


def test_a_learners_row_shows_the_exercise_they_are_on_and_their_mistake():
    assert exercise_now(
        _on("ana", exercise_mistake="publish_on_change", exercise_failed_here=2)
    ) == ("wall_stop ✗ publish on change")
    assert (
        exercise_now(_on("ben", exercise_passed_here=True, exercise_mistake="x_y")) == "wall_stop ✓"
    )
    assert exercise_now(_on("cai", exercise_failed_here=1)) == "wall_stop ✗"  # no reason sent
    assert exercise_now(_on("dan")) == "wall_stop"  # not checked yet
    rows = table([_on("ana", exercise_mistake="front_is_index_zero")], StuckRule(), NOW)
    assert dict(zip(COLUMNS, rows[0], strict=True))["exercise now"] == (
        "wall_stop ✗ front is index zero"
    )


def test_the_class_exercises_count_passes_and_group_failures_by_mistake():
    records = [
        _on("learner10", exercise_mistake="front_is_index_zero", exercise_failed_here=1),
        _on("learner2", exercise_mistake="front_is_index_zero", exercise_failed_here=3),
        _on("cai", exercise_mistake="publish_on_change", exercise_failed_here=1),
        _on("dan", exercise_failed_here=2),  # failed before mistakes were kept
        _on("eve"),  # on it, not checked yet: trying, in no group
        _on("fay", exercise_passed_here=True, exercise_mistake="front_is_index_zero"),
        _on("gus", exercise_passed_here=True),
        _on("hal", exercise="counter_publisher", exercise_mistake="talker_rate"),
        _learner("ivy"),  # on no exercise: in no line
    ]
    assert class_exercises(records) == [
        "counter_publisher: 0 passed, 1 trying — talker rate: hal",
        "wall_stop: 2 passed, 5 trying — front is index zero: learner2, learner10; "
        "failed, reason not known: dan; publish on change: cai",
    ]
    [_, wall] = tally_exercises(records)
    assert wall.passed == ("fay", "gus") and "eve" in wall.trying
    assert class_exercises([]) == []


def test_the_class_exercises_name_learners_as_the_page_knows_them():
    records = [
        _on("lti-1", exercise_mistake="stop before the wall"),
        _on("lti-2", exercise_mistake="stop before the wall"),
    ]
    assert class_exercises(records, {"lti-1": "Ada Lovelace"}) == [
        "wall_stop: 0 passed, 2 trying — “stop before the wall” failed: Ada Lovelace, lti-2"
    ]
    two_sites = [_on("learner1", site="A", exercise_mistake="adds"), _on("learner1", site="B")]
    assert class_exercises(two_sites) == ["wall_stop: 0 passed, 2 trying — adds: learner1 (A)"]


def test_the_csv_has_the_mistake_of_each_learner():
    parsed = list(
        csv.DictReader(
            io.StringIO(
                to_csv([_on("ana", exercise_mistake="publish_on_change")], StuckRule(), NOW)
            )
        )
    )
    assert parsed[0]["exercise_mistake"] == "publish_on_change"


def test_the_teacher_page_shows_the_class_exercises_and_a_learners_mistake(tmp_path):
    from app.teacher.page import LocalAttempts, exercises_markdown, learner_detail

    records = [
        _on("ana", exercise_mistake="front_is_index_zero", exercise_failed_here=1),
        _on("ben", exercise_passed_here=True),
    ]
    shown = exercises_markdown(records)
    assert shown.startswith("### Exercises across the class\n\n- ")
    assert "wall\\_stop: 1 passed, 1 trying — front is index zero: ana" in shown
    assert "No learner is on an exercise yet" in exercises_markdown([_learner("cai")])
    detail = learner_detail(records[0])
    assert "1 failed; last failure: front is index zero" in detail
    assert "Newest attempt" not in detail  # no folder to show

    # On the classroom's machine the page finds the learner's newest attempt.
    folder = tmp_path / "bags" / "ana" / "attempts" / "wall_stop"
    older = folder / "20261129-101500-seed4242-fail"
    newest = folder / "20261129-101900-seed77-fail"
    for attempt in (older, newest):
        attempt.mkdir(parents=True)
    (newest / "20261129-101900-seed77-fail_0.mcap").write_bytes(b"")
    attempts = LocalAttempts(tmp_path / "bags", site="A")
    assert attempts.newest(records[0]) == newest
    detail = learner_detail(records[0], attempts.newest(records[0]))
    assert f"`{newest}`" in detail and f"`{newest}/20261129-101900-seed77-fail_0.mcap`" in detail
    assert "2026-11-29 10:19:00 UTC · fail · seed 77" in detail
    assert "Watch this attempt" in detail
    # Another site's learner of the same name, or a name that is no name, reaches no folder.
    assert attempts.newest(replace(records[0], site="B")) is None
    assert attempts.newest(replace(records[0], exercise="../../etc")) is None
    assert attempts.newest(replace(records[0], learner="..")) is None
    assert attempts.newest(_on("ben")) is None  # nothing kept
