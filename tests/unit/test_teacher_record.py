"""The teacher's table: the stuck rule, the rows, the CSV, and the message's bounds."""

from __future__ import annotations

import csv
import io

from app.teacher import wire
from app.teacher.record import (
    COLUMNS,
    MAX_CODE,
    LearnerRecord,
    StuckRule,
    checks_text,
    table,
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
    )
    msg = wire.to_message(record)
    back = wire.from_message(msg, received_at=NOW)
    assert len(back.code_excerpt) == MAX_CODE and back.code_excerpt.endswith("…")
    assert len(back.lesson_title) == 120
    assert len(back.check_states) == 16 == len(back.check_reasons)
    assert back.nodes_running == ("talker", "listener")
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
