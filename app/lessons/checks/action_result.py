"""Check ``action_result``: the goal sent by this step ended with the status."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "action_result",
    required="action status",
    words="the goal sent by this step ended with the status",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    with rt.lock:
        run = rt.goals.get(c["action"])
    if run is None:
        return CheckResult(FAIL, f"no goal sent to {c['action']} yet")
    status = run.outcome
    if status == "running":
        done = len(run.feedback)
        return CheckResult(WAITING, f"goal running, {done} feedback messages so far")
    if run.error:
        return CheckResult(FAIL, run.error)
    if status == c["status"]:
        return CheckResult(PASS, f"the goal {status}")
    return CheckResult(FAIL, f"the goal {status}, expected {c['status']}{_why(run.result)}")


def _why(result: object) -> str:
    """' (error CODE: message)' from a result that says why (Nav2's actions do), else ''."""
    code = getattr(result, "error_code", 0)
    message = str(getattr(result, "error_msg", "") or "").strip()
    if not code and not message:
        return ""
    return f" (error {code}: {message})" if message else f" (error {code})"
