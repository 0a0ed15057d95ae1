"""Make rclpy's parameter services refuse what they cannot handle instead of dying.

Why: every rclpy node offers ``~/set_parameters`` and
``~/set_parameters_atomically``. Two bugs of rclpy 7.1.6 (the Jazzy wheel)
sit behind them:

- each ``rcl_interfaces/ParameterValue`` becomes a ``Parameter`` through
  ``Parameter.Type(value.type)``; a type code outside 0..9 (any client can
  send 99) raises ``ValueError`` inside the service callback, the exception
  leaves ``rclpy.spin`` and the node process ends;
- the check for undeclared names uses ``any(names)``, which skips the empty
  name: setting a parameter called "" quietly declares it, on a node that
  allows no undeclared parameters.

rclcpp refuses both with ``successful: false``. ``guard_parameter_services()``
wraps the two callbacks once per process so rclpy answers the same way; every
request without such a parameter goes to rclpy's own code, unchanged.

``nodes/__init__.py`` calls it, so every node of the course (and every node a
learner writes under ``nodes/``) is covered without a line in the node.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

from rcl_interfaces.msg import Parameter as ParameterMsg
from rcl_interfaces.msg import SetParametersResult
from rcl_interfaces.srv import SetParameters, SetParametersAtomically
from rclpy.parameter import Parameter
from rclpy.parameter_service import ParameterService

KNOWN_TYPES = frozenset(t.value for t in Parameter.Type)
_GUARDED = "_classroom_guarded"


def refusal_reason(param: ParameterMsg) -> str | None:
    """Why ``param`` must be refused before rclpy sees it, or None to let rclpy decide."""
    if not param.name:
        return "a parameter name must not be empty"
    if param.value.type in KNOWN_TYPES:
        return None
    name = param.name if len(param.name) <= 60 else f"{param.name[:60]}..."
    return (
        f"parameter {name!r}: unknown parameter type {param.value.type} "
        f"(rcl_interfaces/ParameterType defines {min(KNOWN_TYPES)}..{max(KNOWN_TYPES)})"
    )


def _guard_set_parameters(original: Callable[..., Any]) -> Callable[..., Any]:
    @functools.wraps(original)
    def on_set_parameters(
        self: ParameterService, request: SetParameters.Request, response: SetParameters.Response
    ) -> SetParameters.Response:
        if not any(refusal_reason(p) for p in request.parameters):
            return original(self, request, response)
        # rclpy sets the parameters of this service one at a time; so do we, in order.
        for param in request.parameters:
            reason = refusal_reason(param)
            if reason is None:
                one = original(self, SetParameters.Request(parameters=[param]), type(response)())
                response.results.extend(one.results)
            else:
                response.results.append(SetParametersResult(successful=False, reason=reason))
        return response

    return on_set_parameters


def _guard_set_parameters_atomically(original: Callable[..., Any]) -> Callable[..., Any]:
    @functools.wraps(original)
    def on_set_parameters_atomically(
        self: ParameterService,
        request: SetParametersAtomically.Request,
        response: SetParametersAtomically.Response,
    ) -> SetParametersAtomically.Response:
        reasons = [r for r in map(refusal_reason, request.parameters) if r]
        if not reasons:
            return original(self, request, response)
        response.result = SetParametersResult(successful=False, reason="; ".join(reasons[:3]))
        return response

    return on_set_parameters_atomically


def guard_parameter_services() -> None:
    """Patch ``ParameterService`` (idempotent); affects nodes created afterwards."""
    if getattr(ParameterService, _GUARDED, False):
        return
    for name, guard in (
        ("_set_parameters_callback", _guard_set_parameters),
        ("_set_parameters_atomically_callback", _guard_set_parameters_atomically),
    ):
        setattr(ParameterService, name, guard(getattr(ParameterService, name)))
    setattr(ParameterService, _GUARDED, True)
