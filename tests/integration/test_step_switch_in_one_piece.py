"""A new step reaches the page in one piece: never its title with the last step's buttons.

A step's switch is a dozen updates (title, text, stage, the step's buttons removed and
added, checks, Next's label). Sent as they were made, a page could draw the new title
before the new buttons came, and the step card's Next moved up and back down. The busy
rehearsal ci127 lost a click on Next so: the course walk at 125 % zoom pressed it on lesson
3's step 2, and the page stayed there. The dashboard now sends a switch as one of viser's
atomic groups, which a page draws at once. This test walks three lessons and looks at
what a page would draw after each frame it is sent.

A page's first load is not a switch: viser sent everything the page must show in
windows of at most 128 messages, so a card could arrive a frame before its buttons (the
busy CI run of 1678878 saw lesson 1's first card so). Judging starts once that first load
shows a whole card, before the test makes its first switch.

The same cap cut a switch queued behind a burst (the busy rehearsal ci150: step 2's title
with step 1's buttons, while the tools this client asks for were being built); our
servers now send what waits in one window (app/viser_threads.py,
tests/faults/test_viser_atomic.py).
"""

from __future__ import annotations

import re

import pytest

from app.lessons.panel import action_button_label, answer_button_label
from tests.conftest import wait_until
from tests.course_data import shared_course
from tests.wire_client import NEXT_OR_SKIP, WireClient

pytestmark = pytest.mark.ros

LESSONS = ("01_ros2_and_dds", "02_turtlesim_cli", "03_turtlesim_record_launch")
CARD = re.compile(r"^Step (\d+) of (\d+): (.*)$")


def _buttons(step) -> frozenset[str]:
    """The buttons the step card shows for ``step`` (app/lessons/panel.py): one per
    action, then each quiz's answers, none chosen."""
    labels = [action_button_label(action) for action in step.actions]
    labels += [
        answer_button_label(option, False)
        for check in step.checks
        if check.kind == "quiz"
        for option in check["options"]
    ]
    return frozenset(labels)


def test_every_frame_shows_one_steps_title_with_that_steps_buttons(dashboard):
    course = shared_course()
    lessons = [course.lesson(lesson_id) for lesson_id in LESSONS]
    # (step count, title) -> that step's buttons; None where two steps share the key.
    buttons_of: dict[tuple[int, str], frozenset[str] | None] = {}
    for lesson in lessons:
        assert lesson is not None
        for step in lesson.steps:
            key, labels = (len(lesson.steps), step.title), _buttons(step)
            buttons_of[key] = labels if buttons_of.get(key, labels) == labels else None
    wrong: list[str] = []
    judged: set[tuple[int, str]] = set()
    client = WireClient(dashboard.url)

    def judge() -> tuple[tuple[int, str], str | None] | None:
        """The step card's key and, if its buttons are wrong, what was drawn; None when
        there is no single card with a known title. Called under the client's lock."""
        gui = client.gui
        cards = [
            (uuid, CARD.match(str(p.get("label"))))
            for uuid, p in gui.items()
            if p["type"] == "GuiFolderMessage" and CARD.match(str(p.get("label")))
        ]
        if len(cards) != 1:
            return None
        card, match = cards[0]
        assert match is not None
        key = (int(match.group(2)), match.group(3))
        expected = buttons_of.get(key)
        if expected is None:
            return None  # a step of another lesson, or a title two steps share
        # The step's own buttons sit in an unlabelled folder of the card.
        holders = {
            uuid
            for uuid, p in gui.items()
            if p["type"] == "GuiFolderMessage"
            and p.get("container_uuid") == card
            and p.get("label") is None
        }
        shown = {
            str(p.get("label"))
            for p in gui.values()
            if p["type"] == "GuiButtonMessage" and p.get("container_uuid") in holders
        }
        return key, (
            None if shown == expected else f"{match.group(0)!r} drawn with {sorted(shown)}"
        )

    def look() -> None:  # the client's reader, under its lock, after each frame
        verdict = judge()
        if verdict is not None:
            judged.add(verdict[0])
            if verdict[1] is not None:
                wrong.append(verdict[1])

    def first_load_whole() -> bool:
        with client.lock:
            verdict = judge()
            if verdict is None or verdict[1] is not None:
                return False
            judged.add(verdict[0])
            client.on_frame = look  # from here on, every frame is judged
            return True

    try:
        picker = wait_until(
            lambda: client.find("Lesson", "GuiDropdownMessage"), timeout=60, what="Lesson"
        )
        wait_until(first_load_whole, timeout=60, what="the first load's whole step card")
        switches = 0
        for lesson in lessons:
            assert lesson is not None
            client.set_value(picker, f"{lesson.unit:02d} · {lesson.title}")
            for index, step in enumerate(lesson.steps):
                card = f"Step {index + 1} of {len(lesson.steps)}: {step.title}"
                if index:
                    client.click(NEXT_OR_SKIP)
                wait_until(lambda card=card: client.find(card), timeout=20, what=card)
                switches += 1
        assert not wrong, "\n".join(wrong[:10])
        # Every step was judged (none skipped as a title two steps share, or never seen).
        assert len(judged) == switches, (sorted(judged), switches)
    finally:
        client.close()
