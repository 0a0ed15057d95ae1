"""The teacher's gradebook in the teacher service: what went to the LMS, what waits, and Retry.

The service is the real tornado app with its LTI side (tests/lti/service.py),
the LMS the test platform over HTTP, and who is a teacher is decided by the
service's own ``HubOAuth`` asking a stand-in hub for the token's scopes.
"""

from __future__ import annotations

import csv
import html
import io
import json
import re
import time
import urllib.parse
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from app.lti import claims
from app.lti.learners import hub_user_name
from app.teacher.record import GradedAttempt
from tests.lti.platform import TestPlatform
from tests.lti.service import PREFIX, Answer, ServiceUnderTest, request, wait_delivered, wait_for
from tests.lti.test_service import (
    EXERCISE,
    LESSON,
    exercise_record,
    graded_link,
    hub_login,
    launch,
    lesson_record,
    start,
)


@pytest.fixture
def service(platform: TestPlatform, tmp_path: Path) -> Iterator[ServiceUnderTest]:
    running = start(tmp_path / "lti", platform)
    yield running
    running.close()


def as_user(service: ServiceUnderTest, token: str, path: str, **form: str) -> Answer:
    """A browser request of the teacher's pages with a hub token (GET, or POST a form)."""
    headers = {"Authorization": f"token {token}"}
    if not form:
        return request("GET", service.url + PREFIX + path, headers=headers)
    cookie = form.pop("cookie")
    headers["Cookie"] = cookie
    return request("POST", service.url + PREFIX + path, form=form, headers=headers)


def gradebook_lines(service: ServiceUnderTest, token: str) -> list[dict[str, Any]]:
    answer = as_user(service, token, "gradebook.json")
    assert answer.status == 200, answer.body
    lines: list[dict[str, Any]] = json.loads(answer.body)["lines"]
    return lines


def rows(page: str) -> list[str]:
    """The gradebook table's rows (every line, not the class grid) as plain text, one each."""
    body = page.split('<table id="gradebook"', 1)[1].split("<tbody>", 1)[1].split("</tbody>", 1)[0]
    found = re.findall(r"<tr[^>]*>(.*?)</tr>", body, re.S)
    return [html.unescape(re.sub(r"<[^>]+>", " ", row)) for row in found]


def retry_form(page: Answer) -> dict[str, str]:
    """What the browser posts when the teacher presses Retry: the XSRF field and its cookie."""
    field = re.search(r'name="_xsrf" value="([^"]+)"', page.body)
    assert field, page.body
    return {"_xsrf": html.unescape(field.group(1)), "cookie": f"_xsrf={page.cookies['_xsrf']}"}


def test_a_teacher_sees_a_sent_score_a_waiting_one_and_retries_it(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    # Ada opens an exercise and a lesson, each with a grade column; the lesson's column
    # answers 503 for now. Grace (whose LMS sends only given and family names) opens a
    # link without a grade column.
    exercise = graded_link(
        platform.lineitem_url("11"), {"exercise": EXERCISE, "score_maximum": "5"}
    )
    exercise[claims.RESOURCE_LINK] = {"id": "link-3", "title": "Counter (graded)"}
    ada = hub_login(service, launch(service, platform, **exercise))
    lesson = graded_link(platform.lineitem_url("12"), {"lesson": LESSON}, "link-4")
    assert hub_login(service, launch(service, platform, **lesson)) is not None
    grace = hub_login(
        service,
        launch(
            service,
            platform,
            sub="learner-43",
            name=None,
            given_name="Grace",
            family_name="Hopper",
            **{claims.AGS_ENDPOINT: None, claims.CUSTOM: {"lesson": LESSON}},
        ),
    )
    assert ada is not None and grace is not None
    name = ada["name"]
    platform.fail_next("12", 503, "down for maintenance", times=100)
    assert service.report(exercise_record(name, passed=True)).status == 200
    assert service.report(lesson_record(name, step=6, states=("pass", "pass"))).status == 200
    wait_for(lambda: bool(platform.scores["11"]), why="the exercise's score")
    teacher = service.hub.teacher_token("mrs-teacher")
    wait_for(
        lambda: any(
            line["state"] == "waiting" and line["attempts"]
            for line in gradebook_lines(service, teacher)
        ),
        why="the lesson's first try",
    )

    page = as_user(service, teacher, "gradebook")
    assert page.status == 200 and page.headers["content-type"].startswith("text/html")
    assert page.headers["cache-control"] == "no-store"
    sent, waiting, no_column = rows(page.body)  # by the LMS's name: Ada, Ada, Grace
    assert "Ada Lovelace" in sent and name in sent
    assert "A counter on a topic" in sent and "Counter (graded) in Robotics 101" in sent
    assert "✓ sent" in sent and "5 of 5" in sent and "accepted" in sent
    assert "Lesson 5:" in waiting and "… waiting" in waiting and "1 of 1" in waiting
    assert "HTTP 503" in waiting and "down for maintenance" in waiting
    assert re.search(r"in \d+ s \(after 1 try\)", waiting), waiting
    assert "Grace Hopper" in no_column and "no grade column" in no_column
    assert hub_user_name(platform.issuer, "learner-43") in no_column
    assert "1 sent · 1 waiting · 1 no grade column" in page.body
    assert "Retry the outbox now (1 waiting or refused)" in page.body

    # The class page names LMS learners beside their hub names, and links the gradebook.
    table = json.loads(as_user(service, teacher, "progress.json").body)
    assert table["names"] == {name: "Ada Lovelace"}
    assert 'href="gradebook"' in as_user(service, teacher, "").body
    spreadsheet = list(csv.DictReader(io.StringIO(as_user(service, teacher, "progress.csv").body)))
    assert [(r["learner"], r["lms_name"]) for r in spreadsheet] == [(name, "Ada Lovelace")]
    # ...and, as classroom's page does, the exercises across the class (a hub user's failure).
    failed = replace(exercise_record("bob", passed=False), exercise_mistake="wrong_topic")
    assert service.report(failed).status == 200
    table = json.loads(as_user(service, teacher, "progress.json").body)
    assert table["exercises"] == [f"{EXERCISE}: 0 passed, 1 trying — wrong topic: bob"]
    assert "Exercises across the class" in as_user(service, teacher, "").body

    # The LMS is back; the teacher does not wait for the backoff and presses Retry. The
    # tool's clock is held an hour back first: its backoff can then send nothing on its own,
    # however slow this machine is, so only Retry can (no time limit tells them apart).
    service.clock.ahead = -3600.0
    with platform.lock:
        platform.scripted["12"].clear()
    answer = as_user(service, teacher, "gradebook/retry", **retry_form(page))
    assert answer.status == 303 and answer.location == PREFIX + "gradebook?retried=1"
    after = as_user(service, teacher, answer.location.removeprefix(PREFIX))
    assert "Sending 1 score(s) now" in after.body
    # Sent once the tool has the LMS's answer: the LMS keeps the score before it answers,
    # so its list alone was read too early once (ci95: the line still said "waiting").
    wait_for(
        lambda: (
            [line["state"] for line in gradebook_lines(service, teacher)]
            == ["sent", "sent", "no grade column"]
        ),
        why="the retried score, sent as the tool records it",
    )
    assert len(platform.scores["12"]) == 1


def test_a_refused_score_shows_the_lms_reason_and_retry_sends_it_once_fixed(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    link = graded_link(platform.lineitem_url("11"), {"exercise": EXERCISE})
    ada = hub_login(service, launch(service, platform, **link))
    assert ada is not None
    platform.fail_next("11", 400, "this user is not enrolled in the course")
    assert service.report(exercise_record(ada["name"], passed=True)).status == 200
    teacher = service.hub.teacher_token("mrs-teacher")
    wait_for(lambda: gradebook_lines(service, teacher)[0]["state"] == "refused", why="the refusal")
    page = as_user(service, teacher, "gradebook")
    [refused] = rows(page.body)
    assert "✗ refused" in refused and "not enrolled in the course" in refused
    assert "press Retry once fixed in the LMS" in refused
    assert platform.scores["11"] == []
    # The teacher enrols the learner in the LMS, then presses Retry.
    answer = as_user(service, teacher, "gradebook/retry", **retry_form(page))
    assert answer.status == 303
    wait_for(lambda: bool(platform.scores["11"]), why="the score after Retry")
    # The LMS has it before the service has read the LMS's answer (a CI run read "waiting").
    wait_for(
        lambda: [line["state"] for line in gradebook_lines(service, teacher)] == ["sent"],
        why="the gradebook to say sent",
    )
    assert len(platform.scores["11"]) == 1  # sent once


def test_a_learner_without_teacher_rights_is_refused_the_gradebook(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    link = graded_link(platform.lineitem_url("11"), {"exercise": EXERCISE})
    ada = hub_login(service, launch(service, platform, **link))
    assert ada is not None
    platform.fail_next("11", 503, "maintenance", times=100)
    assert service.report(exercise_record(ada["name"], passed=True)).status == 200
    teacher = service.hub.teacher_token("mrs-teacher")
    wait_for(lambda: bool(gradebook_lines(service, teacher)[0]["attempts"]), why="a first try")
    tries = len(platform.score_requests)

    learner = service.hub.token_for(ada["name"])  # a real hub user, with no teacher scope
    history = f"gradebook/attempts?learner={ada['name']}&activity=exercise:{EXERCISE}"
    for path in ("gradebook", "gradebook.json", "gradebook.csv", "", "progress.json", history):
        answer = as_user(service, learner, path)
        assert answer.status == 403, (path, answer.status)
        assert "Ada Lovelace" not in answer.body and "lineitems" not in answer.body
    page = as_user(service, learner, "gradebook")
    assert "the gradebook is for the class&#x27;s teachers" in page.body
    # Nor can a learner press Retry, even with a good XSRF pair from a page of the service.
    teacher_page = as_user(service, teacher, "gradebook")
    refused = as_user(service, learner, "gradebook/retry", **retry_form(teacher_page))
    assert refused.status == 403
    [line] = gradebook_lines(service, teacher)
    assert line["state"] == "waiting" and line["next_try"] > service.clock() + 1  # not due
    assert len(platform.score_requests) == tries
    # Without any hub login, the browser goes to the hub to sign in first.
    anonymous = request("GET", service.url + PREFIX + "gradebook")
    assert anonymous.status == 302 and "/oauth2/authorize" in anonymous.location


def history_links(page: str) -> dict[str, str]:
    """The class grid's cell links, by the activity each opens ("exercise:counter_publisher")."""
    found = {}
    for href in re.findall(r'href="(gradebook/attempts\?[^"]+)"', page):
        href = html.unescape(href)
        query = dict(urllib.parse.parse_qsl(urllib.parse.urlsplit(href).query))
        found[f"{query['learner']} {query['activity']}"] = href
    return found


def page_text(body: str) -> str:
    return html.unescape(re.sub(r"<[^>]+>", " ", body))


def test_a_cell_opens_the_learners_graded_attempts_with_their_seeds_and_the_lms_state(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    link = graded_link(platform.lineitem_url("11"), {"exercise": EXERCISE, "score_maximum": "5"})
    ada = hub_login(service, launch(service, platform, **link))
    assert ada is not None
    name = ada["name"]
    now = time.time()
    tried = (
        GradedAttempt(now - 60, "pass", 4242, 3, 3, (), "3 of 3 checks passed: passed."),
        GradedAttempt(
            now - 300, "fail", 17, 2, 3, ("probe /count: sent 5, <got> 4",), "2 of 3 checks"
        ),
        GradedAttempt(now - 400, "problem", 0, 0, 0, (), "Not graded: your program is not running"),
    )
    # The dashboard reports its newest attempts while the learner is on the exercise.
    record = replace(exercise_record(name, passed=True), exercise_history=tried)
    assert service.report(record).status == 200
    wait_for(lambda: bool(platform.scores["11"]), why="the score")
    wait_delivered(service.lti, why="the LMS's answer to the score")
    # Then moves on to another exercise: its history stays in the gradebook.
    later = replace(exercise_record(name, passed=False, slug="wall_stop"), exercise_history=())
    assert service.report(later).status == 200
    teacher = service.hub.teacher_token("mrs-teacher")

    grid = as_user(service, teacher, "gradebook")
    cell = history_links(grid.body)[f"{name} exercise:{EXERCISE}"]
    page = as_user(service, teacher, cell)
    assert page.status == 200 and page.headers["content-type"].startswith("text/html")
    assert page.headers["cache-control"] == "no-store"
    words = page_text(page.body)
    assert "Ada Lovelace: Exercise (lesson 5): A counter on a topic" in words
    assert "✓ sent" in words and "5 of 5" in words  # what the LMS has
    assert "seed 4242" in words  # ...and what the score told it
    assert f"ros2-classroom exercise check {EXERCISE} FILE --seed 4242" in words
    assert f"ros2-classroom exercise check {EXERCISE} FILE --seed 17" in words
    assert "probe /count: sent 5, <got> 4" in words and "<got>" not in page.body
    assert "⚠ not graded" in words and "your program is not running" in words
    assert "no replay button here: the teacher service runs no ROS 2 graph" in words
    assert "3 shown: 1 passed, 1 failed, 1 not graded" in words


def test_an_address_naming_no_learner_or_activity_of_the_gradebook_gets_a_page(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    link = graded_link(platform.lineitem_url("11"), {"exercise": EXERCISE})
    ada = hub_login(service, launch(service, platform, **link))
    # Grace is in another course, whose link opens the lesson only.
    other = graded_link(platform.lineitem_url("21"), {"lesson": LESSON}, "link-9")
    other[claims.CONTEXT] = {"id": "course-2", "title": "Robotics 102"}
    grace = hub_login(service, launch(service, platform, sub="learner-43", **other))
    assert ada is not None and grace is not None
    teacher = service.hub.teacher_token("mrs-teacher")
    ada_name, grace_name = ada["name"], grace["name"]
    cases = {
        "gradebook/attempts": "names no activity",
        f"gradebook/attempts?learner={ada_name}&activity=bogus": "names no activity",
        f"gradebook/attempts?activity=exercise:{EXERCISE}": "names no learner",
        f"gradebook/attempts?learner=lti-nobody&activity=exercise:{EXERCISE}": (
            "no learner 'lti-nobody' has opened anything from the LMS here"
        ),
        f"gradebook/attempts?learner={ada_name}&activity=exercise:no_such": (
            "Ada Lovelace has no LMS link to exercise 'no_such'"
        ),
        f"gradebook/attempts?learner={grace_name}&activity=exercise:{EXERCISE}": (
            f"has no LMS link to exercise '{EXERCISE}' (it may be another course's activity); "
            "they opened Lesson 5"
        ),
        "gradebook/attempts?learner=%3Cscript%3E&activity=exercise:x": "no learner '<script>'",
    }
    for path, sentence in cases.items():
        answer = as_user(service, teacher, path)
        assert answer.status == 404, (path, answer.status)
        assert answer.headers["content-type"].startswith("text/html")
        assert "Traceback" not in answer.body and "<script>" not in answer.body
        found = re.search(r'<p class="why">(.*?)</p>', answer.body, re.S)
        assert found and sentence in html.unescape(found.group(1)), (path, answer.body)
