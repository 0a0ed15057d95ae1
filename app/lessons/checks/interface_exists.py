"""Check ``interface_exists``: the message, service or action type is installed."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import PASS, CheckResult, register_check
from app.ros.convert import import_type

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "interface_exists", required="type", words="the message, service or action type is installed"
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    import_type(c["type"])  # an unknown type raises -> fail with the reason
    return CheckResult(PASS, f"{c['type']} is installed")
