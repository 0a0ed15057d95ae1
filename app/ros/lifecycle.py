"""Managed (lifecycle) nodes, through their lifecycle_msgs services: state and transitions."""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetAvailableTransitions, GetState

from app.ros.calls import call_service
from app.ros.context import CallContext
from app.ros.errors import Ros2Error
from app.ros.graph import require_node

GET_STATE_TYPE = "lifecycle_msgs/srv/GetState"
PRIMARY_STATES = ("unconfigured", "inactive", "active", "finalized")
# Sent by label, a transition is resolved by the node from its current state
# ("shutdown" exists from unconfigured, inactive and active).
TRANSITION_LABELS = ("configure", "activate", "deactivate", "cleanup", "shutdown")


@dataclass(frozen=True)
class TransitionInfo:
    id: int
    label: str
    start: str
    goal: str


def lifecycle_nodes(ctx: CallContext) -> list[str]:
    """Nodes that serve <node>/get_state with lifecycle_msgs/srv/GetState."""
    out = []
    for name, types in ctx.node.get_service_names_and_types():
        if name.endswith("/get_state") and GET_STATE_TYPE in types:
            out.append(name[: -len("/get_state")] or "/")
    return sorted(out)


def lifecycle_target(ctx: CallContext, fqn: str) -> str:
    """The name of a lifecycle node on the graph, or one clear error."""
    target = fqn if fqn.startswith("/") else "/" + fqn
    if target in lifecycle_nodes(ctx):
        return target  # its services are visible even before its name is discovered
    target = require_node(ctx, fqn)
    if target not in lifecycle_nodes(ctx):
        raise Ros2Error(f"node '{target}' is not a lifecycle (managed) node")
    return target


def get_state(ctx: CallContext, fqn: str) -> tuple[int, str]:
    response = cast(
        GetState.Response, call_service(ctx, f"{fqn}/get_state", GetState, GetState.Request())
    )
    return response.current_state.id, response.current_state.label


def available_transitions(ctx: CallContext, fqn: str) -> list[TransitionInfo]:
    request = GetAvailableTransitions.Request()
    response = cast(
        GetAvailableTransitions.Response,
        call_service(ctx, f"{fqn}/get_available_transitions", GetAvailableTransitions, request),
    )
    return [
        TransitionInfo(t.transition.id, t.transition.label, t.start_state.label, t.goal_state.label)
        for t in response.available_transitions
    ]


def change_state(ctx: CallContext, fqn: str, transition: str) -> tuple[bool, TransitionInfo]:
    """Trigger a transition by label or id; an unavailable one is one clear error."""
    available = available_transitions(ctx, fqn)
    chosen = next((t for t in available if transition in (t.label, str(t.id))), None)
    if chosen is None:
        state = get_state(ctx, fqn)[1]
        labels = ", ".join(t.label for t in available) or "none"
        raise Ros2Error(
            f"transition '{transition}' is not available in state '{state}' of {fqn}; "
            f"available: {labels}"
        )
    request = ChangeState.Request(transition=Transition(id=chosen.id, label=chosen.label))
    response = cast(
        ChangeState.Response, call_service(ctx, f"{fqn}/change_state", ChangeState, request)
    )
    return bool(response.success), chosen


def change_request(label: str) -> ChangeState.Request:
    """A request by label: the node resolves it from its own state (a step button's)."""
    if label not in TRANSITION_LABELS:
        raise Ros2Error(f"unknown lifecycle transition '{label}'")
    return ChangeState.Request(transition=Transition(label=label))
