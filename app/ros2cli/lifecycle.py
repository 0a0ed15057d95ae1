"""`ros2 lifecycle nodes/get/list/set`, through the lifecycle_msgs services of a managed node."""

from __future__ import annotations

from dataclasses import dataclass

from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetAvailableTransitions, GetState

from app.ros2cli.calls import call_service
from app.ros2cli.common import Ros2Error, VerbContext, node_fqn, require_node

GET_STATE_TYPE = "lifecycle_msgs/srv/GetState"


@dataclass(frozen=True)
class TransitionInfo:
    id: int
    label: str
    start: str
    goal: str


def lifecycle_nodes(ctx: VerbContext) -> list[str]:
    """Nodes that serve <node>/get_state with lifecycle_msgs/srv/GetState."""
    out = []
    for name, types in ctx.node.get_service_names_and_types():
        if name.endswith("/get_state") and GET_STATE_TYPE in types:
            out.append(name[: -len("/get_state")] or "/")
    return sorted(out)


def _target(ctx: VerbContext, fqn: str) -> str:
    target = fqn if fqn.startswith("/") else "/" + fqn
    if target in lifecycle_nodes(ctx):
        return target  # its services are visible even before its name is discovered
    name, namespace = require_node(ctx, fqn)
    target = node_fqn(name, namespace)
    if target not in lifecycle_nodes(ctx):
        raise Ros2Error(f"node '{target}' is not a lifecycle (managed) node")
    return target


def get_state(ctx: VerbContext, fqn: str) -> tuple[int, str]:
    response = call_service(ctx, f"{fqn}/get_state", GetState, GetState.Request())
    return response.current_state.id, response.current_state.label


def available_transitions(ctx: VerbContext, fqn: str) -> list[TransitionInfo]:
    request = GetAvailableTransitions.Request()
    response = call_service(
        ctx, f"{fqn}/get_available_transitions", GetAvailableTransitions, request
    )
    return [
        TransitionInfo(t.transition.id, t.transition.label, t.start_state.label, t.goal_state.label)
        for t in response.available_transitions
    ]


def change_state(ctx: VerbContext, fqn: str, transition: str) -> tuple[bool, TransitionInfo]:
    """Trigger a transition by label or id; an unavailable one is one clear error."""
    available = available_transitions(ctx, fqn)
    chosen = next(
        (t for t in available if transition in (t.label, str(t.id))),
        None,
    )
    if chosen is None:
        state = get_state(ctx, fqn)[1]
        labels = ", ".join(t.label for t in available) or "none"
        raise Ros2Error(
            f"transition '{transition}' is not available in state '{state}' of {fqn}; "
            f"available: {labels}"
        )
    request = ChangeState.Request(transition=Transition(id=chosen.id, label=chosen.label))
    response = call_service(ctx, f"{fqn}/change_state", ChangeState, request)
    return bool(response.success), chosen


def verb_nodes(ctx: VerbContext, count: bool = False) -> int:
    nodes = lifecycle_nodes(ctx)
    if count:
        ctx.write(str(len(nodes)))
        return 0
    for name in nodes:
        ctx.write(name)
    return 0


def verb_get(ctx: VerbContext, fqn: str | None = None) -> int:
    targets = [_target(ctx, fqn)] if fqn else lifecycle_nodes(ctx)
    for target in targets:
        state_id, label = get_state(ctx, target)
        ctx.write(f"{label} [{state_id}]" if fqn else f"{target}: {label} [{state_id}]")
    return 0


def verb_list(ctx: VerbContext, fqn: str) -> int:
    target = _target(ctx, fqn)
    for t in available_transitions(ctx, target):
        ctx.write(f"- {t.label} [{t.id}]")
        ctx.write(f"\tStart: {t.start}")
        ctx.write(f"\tGoal: {t.goal}")
    return 0


def verb_set(ctx: VerbContext, fqn: str, transition: str) -> int:
    target = _target(ctx, fqn)
    ok, _chosen = change_state(ctx, target, transition)
    ctx.write("Transitioning successful" if ok else "Transitioning failed")
    return 0 if ok else 1
