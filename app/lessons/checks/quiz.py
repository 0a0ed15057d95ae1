"""Check ``quiz``: the answer chosen is the right one."""

from __future__ import annotations

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
