"""Check ``service_returns``: calling the service answers a field with the value."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check
from app.ros.convert import fill, import_type

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "service_returns",
    required="service type request field equals",
    words="calling the service answers a field with the value",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    srv_type = import_type(c["type"])
    if not rt.services.client(c["service"], srv_type).service_is_ready():
        return CheckResult(FAIL, f"no server for {c['service']}")
    request = fill(srv_type.Request, c["request"])
    response = rt.services.latest(c.key, c["service"], srv_type, request)
    if response is None:
        return CheckResult(WAITING, f"calling {c['service']}")
    value = getattr(response, c["field"])
    if value == c["equals"]:
        return CheckResult(PASS, f"{c['service']} answered {c['field']} = {value!r}")
    return CheckResult(FAIL, f"{c['field']} = {value!r}, expected {c['equals']!r}")
