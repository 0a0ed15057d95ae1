"""Probe ``service_random``: call a service with drawn requests, compare one answer field."""

from __future__ import annotations

from app.exercises.probes.base import (
    ProbeContext,
    expected_value,
    random_inputs,
    register_probe,
    same,
    values_text,
)
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros.calls import call_service
from app.ros.convert import fill, import_type, to_plain
from app.ros.errors import Ros2Error


@register_probe(
    "service_random",
    required="service type inputs field expect",
    optional="calls tolerance",
    words="calls the service with random requests and compares one field of each answer "
    "to the exercise's formula",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    service, srv_type = p["service"], import_type(p["type"], "srv")
    name = f"service {service}"
    examples = []
    for _ in range(p.get("calls", 5)):
        values = random_inputs(ctx.rng, p["inputs"])
        request = fill(srv_type.Request, values)
        try:
            response = call_service(
                ctx.call, service, srv_type, request, timeout=3.0, resend_unanswered=True
            )  # a formula: repeating it is harmless
        except Ros2Error as exc:
            return Result(name, False, f"called with {values_text(values)}: {exc}")
        got = to_plain(getattr(response, p["field"]))
        want = expected_value(p["expect"], values)
        if not same(got, want, p.get("tolerance", 1e-6)):
            return Result(
                name,
                False,
                f"{service} answered {p['field']}={got!r} for {values_text(values)}; "
                f"expected {want!r}",
            )
        examples.append(f"{values_text(values)} -> {got!r}")
    return Result(name, True, f"{len(examples)} random requests answered right, e.g. {examples[0]}")
