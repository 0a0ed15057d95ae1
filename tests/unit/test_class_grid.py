"""The gradebook's class at a glance: a row per learner, a column per activity, the best mark."""

from __future__ import annotations

import re

from app.lti.gradebook import GradebookLine
from app.lti.pages import class_grid, gradebook_page


def line(learner: str, activity: str, state: str, score: str = "", name: str = "") -> GradebookLine:
    return GradebookLine(
        learner=learner,
        lms_name=name,
        activity=activity,
        link="Week 1",
        lineitem="https://lms.example/lineitems/1",
        state=state,  # type: ignore[arg-type]
        score=score,
        queued_at="2026-11-29T10:00:00+00:00",
        sent_at=None,
        lms_answer="",
        attempts=0,
        next_try=None,
        launched_at=0.0,
    )


def cells(page: str) -> list[list[str]]:
    body = page.split("<tbody>", 1)[1].split("</tbody>", 1)[0]
    return [
        [
            re.sub(r"<[^>]+>", "", cell).strip()
            for cell in re.findall(r"<t[hd][^>]*>(.*?)</t[hd]>", row)
        ]
        for row in re.findall(r"<tr>(.*?)</tr>", body)
    ]


def test_each_learner_has_a_row_and_each_activity_a_column_with_the_best_of_its_links():
    grid = class_grid(
        [
            line("lti-b", "exercise wall_stop", "waiting", "5 of 5", name="Ben"),
            line("lti-a", "exercise wall_stop", "refused", "5 of 5", name="ana"),
            line("lti-a", "exercise wall_stop", "sent", "5 of 5", name="ana"),  # a second course
            line("lti-a", "Lesson 5: Topics", "not done", name="ana"),
        ]
    )
    assert re.findall(r"<th>(.*?)</th>", grid)[:3] == [
        "Learner",
        "Lesson 5: Topics",
        "exercise wall_stop",
    ]
    assert cells(grid) == [["ana", "○", "✓ 5 of 5"], ["Ben", "", "… 5 of 5"]]
    assert 'data-show="lti-a"' in grid  # a click filters the lines below to that learner


def test_the_page_shows_the_grid_above_every_line_and_none_without_launches():
    lines = [line("lti-a", "exercise wall_stop", "sent", "5 of 5", name="Ana")]
    page = gradebook_page(lines, now=0.0, retry_form="<form>")
    assert page.index('id="class-grid"') < page.index('id="gradebook"')
    assert class_grid([]) == ""
    assert 'id="class-grid"' not in gradebook_page([], now=0.0, retry_form="<form>")
