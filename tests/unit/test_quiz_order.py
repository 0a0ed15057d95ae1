"""A quiz shows its answers mixed, the same way every time, whatever order the file lists."""

from __future__ import annotations

from collections import Counter

from app.lessons.checks.quiz import answer_order
from app.lessons.panel import LessonsPanel, answer_button_label
from app.lessons.progress import ProgressStore
from app.lessons.schema import Spec
from app.ui.loop import UiLoop
from tests.course_data import shared_course
from tests.unit.fake_gui import FakeGui, FakeHandle

COURSE = shared_course()
QUIZZES = [
    (lesson, index, check)
    for lesson in COURSE.lessons
    for index, step in enumerate(lesson.steps)
    for check in step.checks
    if check.kind == "quiz"
]


def test_the_order_is_a_stable_mix_of_the_same_options():
    quiz = Spec("quiz", {"question": "Q?", "options": ["a", "b", "c", "d"], "answer": "a"})
    shown = answer_order(quiz)
    assert sorted(shown) == ["a", "b", "c", "d"]
    assert answer_order(quiz) == shown  # every showing, every page
    again = Spec("quiz", {**quiz.fields, "options": ["d", "c", "b", "a"]})
    assert answer_order(again) == shown  # the file's order does not leak through


def test_across_the_course_the_right_answer_is_not_always_in_one_place():
    # The files list the right answer first almost always: shown as written, "pick the
    # first" would pass the course's quizzes.
    assert len(QUIZZES) > 20
    written = Counter(check["options"].index(check["answer"]) for _l, _i, check in QUIZZES)
    shown = Counter(answer_order(check).index(check["answer"]) for _l, _i, check in QUIZZES)
    assert written.most_common(1)[0][1] > len(QUIZZES) / 2, "the premise: files put it first"
    assert shown.most_common(1)[0][1] <= len(QUIZZES) / 2, shown


class _Live:
    quiz_answers: dict = {}


class _SideWindow:
    def add_tab(self, *_: object) -> FakeHandle:
        return FakeHandle("tab")


def test_the_step_card_shows_the_answers_in_that_order(tmp_path):
    lesson, index, check = next(q for q in QUIZZES if q[2]["options"][0] == q[2]["answer"])
    progress = ProgressStore(directory=tmp_path)
    progress.set_position(lesson.id, index)
    gui = FakeGui()
    LessonsPanel(gui, UiLoop(), COURSE, _Live(), progress, _SideWindow())  # type: ignore[arg-type]
    labels = {answer_button_label(option, False): option for option in check["options"]}
    shown = [labels[h.label] for h in gui.handles if h.kind == "button" and h.label in labels]
    assert shown == answer_order(check)
    assert shown != list(check["options"])
