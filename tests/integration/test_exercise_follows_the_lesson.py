"""The Exercise tool opens the new lesson's exercise as the lesson opens, not at its next
refresh: a learner who picks another exercise right after Next keeps it.

ci49 (kill_restart, round 17): after a Next into lesson 5 the learner picked the services
exercise and clicked Run, and a refresh a moment later put lesson 5's counter exercise back
and ran that instead.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from tests.conftest import wait_until
from tests.course_data import shared_course, shared_exercises
from tests.wire_client import NEXT_OR_SKIP, WireClient

pytestmark = pytest.mark.ros

FROM, INTO = "04_first_node", "05_topics"
PICKED = "multiply_service"  # an exercise of neither lesson (lesson 7's)
REFRESHES_SEC = 3.0  # the Exercise tool refreshes once a second while idle


@pytest.fixture
def progress_dir(tmp_path) -> Path:
    """The learner is on the last step of lesson 4."""
    course = shared_course()
    steps = len(course.lesson(FROM).steps)  # type: ignore[union-attr]
    folder = tmp_path / "progress"
    folder.mkdir()
    (folder / "default.json").write_text(
        json.dumps(
            {"version": 2, "current": FROM, "lessons": {FROM: {"step": steps - 1, "passed": []}}}
        )
    )
    return folder


BOOK = shared_exercises()


def _label(slug: str) -> str:
    exercise = BOOK.get(slug)
    return f"{exercise.unit:02d} · {exercise.title}"  # as the dropdown names it


def test_a_pick_made_just_after_next_is_kept(dashboard):
    course = shared_course()
    number = [lesson.id for lesson in course.lessons].index(INTO) + 1
    opened = f"Lesson {number} of {len(course.lessons)} · Step 1 of"
    first_of_into = BOOK.for_lesson(INTO)[0].slug
    mine = f"your node: `{BOOK.get(PICKED).node}`"  # the picked exercise's header
    client = WireClient(dashboard.url)
    try:
        picker = wait_until(
            lambda: client.find("Exercise", "GuiDropdownMessage"), timeout=60, what="Exercise"
        )
        assert client.value(picker) == _label(BOOK.for_lesson(FROM)[0].slug)
        client.set_value(picker, _label(PICKED))
        wait_until(lambda: mine in client.markdown(), what="the picked exercise shown")

        # What the dropdown showed when the new lesson's position line arrived.
        shown_then: list[object] = []

        def note(message: dict[str, object]) -> None:  # the client's reader, under its lock
            if not shown_then and opened in str(message.get("updates", "")):
                shown_then.append(client.gui[picker].get("value"))

        client.on_message = note
        client.click(NEXT_OR_SKIP)
        wait_until(lambda: shown_then, what=opened)
        # The new lesson's exercise is sent before the line that says the lesson opened.
        assert shown_then == [_label(first_of_into)]

        client.set_value(picker, _label(PICKED))  # the learner's own pick, at once
        time.sleep(REFRESHES_SEC)
        assert mine in client.markdown(), "a refresh undid the learner's pick"
        # (A page is not sent back the value it set: the dropdown's value changes here only
        # when the dashboard changes it.)
        assert client.value(picker) == _label(first_of_into), "the dashboard moved the pick"
    finally:
        client.close()
