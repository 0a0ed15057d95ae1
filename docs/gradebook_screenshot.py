"""The teacher's gradebook for the docs: a class of four launched from an LMS, two pictures.

The teacher service runs as the LTI tests run it (tests/lti/service.py: the real
tornado app and its LTI side, a stand-in hub for logins), the LMS is the tests'
LTI 1.3 platform over HTTP. Four learners launch an exercise link and a lesson
link; their dashboards report what they did; the lesson's grade column is down
for one of them, so a score waits in the outbox. The pictures: the class grid
with its lines (docs/images/gradebook.png) and one cell's attempt history
(docs/images/gradebook-attempts.png). Called by docs/screenshots.py (part
"gradebook").
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

from playwright.sync_api import Browser, expect

from app.lti import claims
from app.lti.keys import ToolKeys
from app.teacher.record import GradedAttempt
from tests.lti.platform import TestPlatform
from tests.lti.service import PREFIX, wait_for
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

# (LMS user id, name, exercise passed?, lesson finished?)
CLASS = (
    ("learner-1", "Ada Lovelace", True, True),
    ("learner-2", "Alan Turing", False, True),
    ("learner-3", "Katherine Johnson", True, True),
    ("learner-4", "Grace Hopper", True, True),
)
DOWN = "Grace Hopper"  # the lesson's grade column is down from her score on: it waits


def _attempts(passed: bool) -> tuple[GradedAttempt, ...]:
    now = time.time()
    tried = [
        GradedAttempt(now - 900, "problem", 0, 0, 0, (), "Not graded: your program is not running"),
        GradedAttempt(
            now - 600,
            "fail",
            5120,
            2,
            3,
            ("probe /count: sent 5 numbers, 4 came back",),
            "2 of 3 checks passed",
        ),
    ]
    if passed:
        tried.append(GradedAttempt(now - 120, "pass", 4242, 3, 3, (), "3 of 3 checks passed."))
    return tuple(reversed(tried))  # newest first, as a dashboard reports them


def gradebook(browser: Browser, images: Path, tmp: str) -> None:
    platform = TestPlatform()
    platform.tool_jwks = ToolKeys.load_or_create(Path(tmp) / "keys").public_jwks()
    service = start(Path(tmp) / "lti", platform)
    try:
        exercise = graded_link(
            platform.lineitem_url("11"), {"exercise": EXERCISE, "score_maximum": "5"}
        )
        exercise[claims.RESOURCE_LINK] = {"id": "link-3", "title": "Counter (graded)"}
        lesson = graded_link(platform.lineitem_url("12"), {"lesson": LESSON}, "link-4")
        for sub, name, passed, finished in CLASS:
            learner = None
            for link in (exercise, lesson):
                learner = hub_login(service, launch(service, platform, sub=sub, name=name, **link))
            assert learner is not None
            hub_name = learner["name"]
            # Minutes each spent, as their dashboards would have counted them (a made-up class).
            minutes = 14 + 9 * int(sub.rsplit("-", 1)[1])
            spent = (("exercise:" + EXERCISE, minutes * 60), ("lesson:" + LESSON, minutes * 95))
            record = replace(
                exercise_record(hub_name, passed),
                exercise_history=_attempts(passed),
                time_spent=spent,
            )
            assert service.report(record).status == 200
            if name == DOWN:
                platform.fail_next("12", 503, "down for maintenance", times=100)
            step = 6 if finished else 3
            states = ("pass", "pass") if finished else ("pass", "fail")
            assert service.report(lesson_record(hub_name, step, states)).status == 200
        wait_for(lambda: len(platform.scores["11"]) == 3, why="the three exercise scores")
        teacher = service.hub.teacher_token("mrs-teacher")
        context = browser.new_context(
            viewport={"width": 1500, "height": 900},
            extra_http_headers={"Authorization": f"token {teacher}"},
        )
        page = context.new_page()
        page.goto(service.url + PREFIX + "gradebook")
        expect(page.get_by_text("Katherine Johnson").first).to_be_visible(timeout=20_000)
        page.screenshot(path=str(images / "gradebook.png"), full_page=True)
        page.locator('a[href*="gradebook/attempts"]').first.click()
        expect(page.get_by_text("--seed 4242").first).to_be_visible(timeout=20_000)
        page.screenshot(path=str(images / "gradebook-attempts.png"), full_page=True)
        context.close()
    finally:
        service.close()
        platform.close()
