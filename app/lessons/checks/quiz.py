"""Check ``quiz``: the answer chosen is the right one."""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "quiz", required="question options answer", words="the answer chosen is the right one"
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    answer = rt.quiz_answers.get(c.key)
    if answer is None:
        return CheckResult(WAITING, "choose an answer")
    if answer == c["answer"]:
        return CheckResult(PASS, "correct")
    return CheckResult(FAIL, f"{answer!r} is not right; try again")


def answer_order(c: Spec) -> list[str]:
    """The options in the order a learner sees them: mixed, and the same at every showing.

    The course's files list the right answer first (65 of 69 quizzes), so shown as written
    "always pick the first" passed every quiz. A hash of the question and the option ranks
    them: no state to keep, the same on every page, reload and machine.
    """

    def rank(option: str) -> bytes:
        return hashlib.sha256(f"{c['question']}\n{option}".encode()).digest()

    return sorted(c["options"], key=rank)
