"""`ros2 lifecycle nodes/get/list/set` (the services themselves: app.ros.lifecycle)."""

from __future__ import annotations

from app.ros.context import CallContext
from app.ros.lifecycle import (
    available_transitions,
    change_state,
    get_state,
    lifecycle_nodes,
    lifecycle_target,
)
from app.ros2cli.common import write_names


def verb_nodes(ctx: CallContext, count: bool = False) -> int:
    return write_names(ctx, lifecycle_nodes(ctx), count)


def verb_get(ctx: CallContext, fqn: str | None = None) -> int:
    targets = [lifecycle_target(ctx, fqn)] if fqn else lifecycle_nodes(ctx)
    for target in targets:
        state_id, label = get_state(ctx, target)
        ctx.write(f"{label} [{state_id}]" if fqn else f"{target}: {label} [{state_id}]")
    return 0


def verb_list(ctx: CallContext, fqn: str) -> int:
    target = lifecycle_target(ctx, fqn)
    for t in available_transitions(ctx, target):
        ctx.write(f"- {t.label} [{t.id}]")
        ctx.write(f"\tStart: {t.start}")
        ctx.write(f"\tGoal: {t.goal}")
    return 0


def verb_set(ctx: CallContext, fqn: str, transition: str) -> int:
    target = lifecycle_target(ctx, fqn)
    ok, _chosen = change_state(ctx, target, transition)
    ctx.write("Transitioning successful" if ok else "Transitioning failed")
    return 0 if ok else 1
