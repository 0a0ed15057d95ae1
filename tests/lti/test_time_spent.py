"""Time spent per learner and activity: counted by the dashboard, carried by the report,
kept by the hub, shown in the gradebook's grid, its every-line table and the history page.

Pure and fast: the counting is driven with explicit clocks, the pages are rendered
from plain lines; one test goes through the real teacher service (tests/lti/service.py).
"""

from __future__ import annotations

import html
import json
import re
from dataclasses import replace
from pathlib import Path

import pytest

from app.lti.gradebook import GradebookLine
from app.lti.pages import TIME_SPENT_HELP, attempts_page, class_grid, duration, gradebook_page
from app.lti.time_book import TimeBook
from app.teacher.http_report import ReportError, from_json, to_json
from app.teacher.record import LearnerRecord
from app.teacher.time_spent import IDLE_AFTER_SEC, TimeSpent, file_for, read_totals
from tests.lti.platform import TestPlatform
from tests.lti.service import PREFIX, request, wait_for
from tests.lti.test_service import (
    EXERCISE,
    LESSON,
    exercise_record,
    graded_link,
    hub_login,
    launch,
    start,
)

L, X = f"lesson:{LESSON}", f"exercise:{EXERCISE}"


# The dashboard's count -----------------------------------------------------------------


def test_only_active_time_on_the_current_activities_counts(tmp_path: Path) -> None:
    spent = TimeSpent(tmp_path / "learner1.time.json", idle_after=300.0, max_step=5.0)
    spent.tick(1000.0, last_activity=1000.0, current=[L, X])  # the first tick: nothing yet
    for now in range(1001, 1061):  # a minute of work on the exercise
        spent.tick(float(now), last_activity=float(now), current=[L, X])
    for now in range(1061, 1121):  # a minute reading the lesson
        spent.tick(float(now), last_activity=1060.0, current=[L])
    assert dict(spent.totals()) == {L: 120, X: 60}
    # Nothing done for more than five minutes: the dashboard still open counts nothing.
    for now in range(1361, 1400):
        spent.tick(float(now), last_activity=1060.0, current=[L, X])
    # A laptop that slept an hour between two ticks counts one step (5 s), not an hour.
    spent.tick(5000.0, last_activity=5000.0, current=[L])
    spent.tick(9000.0, last_activity=9000.0, current=[L])
    assert dict(spent.totals()) == {L: 130, X: 60}
    spent.tick(9001.0, last_activity=9001.0, current=["../etc", "lesson:a b"])  # never a key
    assert dict(spent.totals()) == {L: 130, X: 60}


def test_a_restarted_dashboard_goes_on_from_its_file(tmp_path: Path) -> None:
    path = file_for(tmp_path / "learner1.json")
    assert path == tmp_path / "learner1.time.json"
    spent = TimeSpent(path)
    for now in range(0, 40):  # saves by itself every 30 s
        spent.tick(float(now), last_activity=float(now), current=[L])
    assert read_totals(path) == {L: 31}  # 30 s after the first count
    spent.save()  # as the beacon does when the dashboard closes
    again = TimeSpent(path)
    assert dict(again.totals()) == {L: 39}
    again.tick(100.0, 100.0, [L])
    again.tick(101.0, 101.0, [L])
    assert dict(again.totals()) == {L: 40}
    path.write_text("{not json")
    assert dict(TimeSpent(path).totals()) == {}  # unreadable: from zero, never a crash
    blocked = TimeSpent(tmp_path / "a_file" / "x.time.json")
    (tmp_path / "a_file").write_text("")
    blocked.tick(0.0, 0.0, [L])
    blocked.tick(1.0, 1.0, [L])
    blocked.save()  # cannot be written: said in the log, counted on in memory
    assert dict(blocked.totals()) == {L: 1}


def test_time_reads_as_a_teacher_says_it() -> None:
    assert [duration(s) for s in (None, 59, 60, 3599, 3600, 7500)] == [
        "–", "< 1 min", "1 min", "59 min", "1 h 00 min", "2 h 05 min"]  # fmt: skip
    # The gradebook (which cannot import the dashboard's side) tells the same rule.
    assert f"in the last {IDLE_AFTER_SEC / 60:g} minutes" in TIME_SPENT_HELP


# The report and the hub's keeping -------------------------------------------------------

RECORD = LearnerRecord(site="hub", learner="lti-abc", time_spent=((L, 754), (X, 300)))


def test_the_report_carries_the_time_and_refuses_a_bad_one() -> None:
    assert from_json(to_json(RECORD), received_at=1.0).time_spent == ((L, 754), (X, 300))
    data = json.loads(to_json(RECORD))
    for bad, reason in [
        ({"lesson:x": 3}, "list of"),
        ([["lesson:x"]], "pairs"),
        ([["../x", 3]], "lesson:ID or exercise:SLUG"),
        ([["lesson:x", -1]], "whole number"),
        ([["lesson:x", 1.5]], "whole number"),
        ([["lesson:x", True]], "whole number"),
        ([["lesson:x", 1]] * 201, "at most 200"),
    ]:
        with pytest.raises(ReportError, match=reason):
            from_json(json.dumps({**data, "time_spent": bad}).encode(), received_at=0.0)


def test_the_hub_keeps_the_larger_total_across_restarts(tmp_path: Path) -> None:
    book = TimeBook(tmp_path, save_every=0.0)
    book.update("lti-abc", [(L, 600), (X, 120)], now=1.0)
    book.update("lti-abc", [(L, 30), (X, 180)], now=2.0)  # a dashboard that lost its file
    assert (book.of("lti-abc", "lesson", LESSON), book.of("lti-abc", "exercise", EXERCISE)) == (
        600, 180)  # fmt: skip
    book.update("../etc", [(L, 5)], now=3.0)
    book.update("lti-abc", [("exercise:../x", 5)], now=3.0)
    again = TimeBook(tmp_path)
    assert again.of("lti-abc", "lesson", LESSON) == 600
    assert (
        again.of("lti-abc", "exercise", "other") is None
        and again.of("lti-b", "lesson", "x") is None
    )
    (tmp_path / "time_spent.json").write_text("[")
    assert TimeBook(tmp_path).of("lti-abc", "lesson", LESSON) is None


def test_the_hub_writes_its_file_at_most_once_a_minute(tmp_path: Path) -> None:
    book = TimeBook(tmp_path, save_every=60.0)
    book.update("lti-abc", [(L, 10)], now=100.0)  # the first: written
    book.update("lti-abc", [(L, 20)], now=110.0)  # ten seconds later: in memory only
    assert TimeBook(tmp_path).of("lti-abc", "lesson", LESSON) == 10
    book.save()  # as the service does when it stops
    assert TimeBook(tmp_path).of("lti-abc", "lesson", LESSON) == 20


# The pages ------------------------------------------------------------------------------


def line(**changes: object) -> GradebookLine:
    base = GradebookLine(
        learner="lti-abc",
        lms_name="Ada",
        activity="A counter on a topic",
        link="Week 3",
        lineitem="https://lms.example/lineitems/7",
        state="sent",
        score="5 of 5",
        queued_at="2026-11-29T10:20:01+00:00",
        sent_at=1795947602.0,
        lms_answer="",
        attempts=1,
        next_try=None,
        launched_at=1795947000.0,
        kind="exercise",
        slug=EXERCISE,
        time_spent=754,
    )
    return replace(base, **changes)  # type: ignore[arg-type]


def text(page: str) -> str:
    return html.unescape(re.sub(r"<[^>]+>", " ", page))


def test_the_grid_the_table_and_the_history_show_the_time_spent() -> None:
    lesson = line(kind="lesson", slug=LESSON, activity="Lesson 5", state="not done", score="",
                  time_spent=None)  # fmt: skip
    tried = line(graded=3, last_graded=1795947600.0)  # 2026-11-29 10:20 UTC
    grid = class_grid([tried, lesson])
    tips = [
        html.unescape(t)
        for t in re.findall(r'<a href="gradebook/attempts[^"]+" title="([^"]+)"', grid)
    ]
    assert tips == [
        "✓ sent 5 of 5: Ada, A counter on a topic; time spent 12 min; "
        "3 graded attempts, the last 2026-11-29 10:20 UTC; its attempts",
        "not done yet : Ada, Lesson 5; time spent –; a lesson: no graded attempts; its attempts",
    ]
    none_yet = class_grid([line()])
    assert "no graded attempt known" in html.unescape(none_yet)
    page = gradebook_page([tried, lesson], now=0.0, retry_form="<form>")
    head = text(page.split('<table id="gradebook"', 1)[1].split("</thead>", 1)[0]).split()
    assert "Time" in head and head.index("Score") + 1 == head.index("Time")
    assert head.index("Graded") == head.index("spent") + 1  # "Time spent", then "Graded ..."
    body = page.split('<table id="gradebook"', 1)[1].split("<tbody>", 1)[1]
    cells = re.findall(r'<td class="time nowrap">([^<]*)</td>', body)
    assert cells == ["12 min", "–"]
    graded = [text(c).split() for c in re.findall(r'<td class="graded">(.*?)</td>', body)]
    assert graded[0][:2] == ["3", "last"] and graded[1] == ["–"]
    history = attempts_page([line()], learner="lti-abc", kind="exercise", slug=EXERCISE,
                            source=None, now=0.0)  # fmt: skip
    assert "Time spent on it: 12 min" in text(history)
    assert "last 5 minutes" in text(history)
    none_yet = attempts_page([lesson], learner="lti-abc", kind="lesson", slug=LESSON,
                             source=None, now=0.0)  # fmt: skip
    assert "Time spent on it: – " in text(none_yet) and "none reported yet" in text(none_yet)


# Through the teacher service ----------------------------------------------------------


def test_a_learners_reported_time_reaches_the_gradebook(
    platform: TestPlatform, tmp_path: Path
) -> None:
    service = start(tmp_path / "lti", platform)
    try:
        link = graded_link(
            platform.lineitem_url("11"), {"exercise": EXERCISE, "score_maximum": "5"}
        )
        ada = hub_login(service, launch(service, platform, **link))
        assert ada is not None
        name = ada["name"]
        record = replace(exercise_record(name, passed=False), time_spent=((L, 1500), (X, 754)))
        assert service.report(record).status == 200
        teacher = service.hub.teacher_token("mrs-teacher")
        headers = {"Authorization": f"token {teacher}"}

        def lines() -> list[dict[str, object]]:
            answer = request("GET", service.url + PREFIX + "gradebook.json", headers=headers)
            found: list[dict[str, object]] = json.loads(answer.body)["lines"]
            return found

        wait_for(lambda: bool(lines()), why="the gradebook's line")
        [only] = lines()
        assert (only["kind"], only["slug"], only["time_spent"]) == ("exercise", EXERCISE, 754)
        grid = request("GET", service.url + PREFIX + "gradebook", headers=headers).body
        assert "time spent 12 min" in html.unescape(grid)
    finally:
        service.close()
    # A restarted service still shows it (kept beside the outbox).
    again = start(tmp_path / "lti", platform)
    try:
        assert again.lti.time_spent_of(name, "exercise", EXERCISE) == 754
    finally:
        again.close()


def test_the_gradebook_downloads_as_csv_with_formulas_made_inert() -> None:
    """What a teacher opens in a spreadsheet: a row per line, and an LMS name that a
    spreadsheet would run as a formula is written as text."""
    import csv
    import io

    from app.lti.gradebook import CSV_COLUMNS, gradebook_csv

    tried = line(graded=3, last_graded=1795947600.0, lms_name="=HYPERLINK(1)")
    lesson = line(kind="lesson", slug=LESSON, activity="Lesson 5", state="not done", score="",
                  time_spent=None)  # fmt: skip
    rows = list(csv.DictReader(io.StringIO(gradebook_csv([tried, lesson]))))
    assert list(rows[0]) == list(CSV_COLUMNS) and len(rows) == 2
    first, second = rows
    assert first["lms_name"].startswith("'=HYPERLINK")  # text, not a formula
    assert (first["state"], first["score"], first["time_spent_s"]) == ("sent", "5 of 5", "754")
    assert first["graded_attempts"] == "3" and first["last_graded_utc"].startswith(
        "2026-11-29T10:20"
    )
    assert (second["kind"], second["time_spent_s"], second["graded_attempts"]) == ("lesson", "", "")
