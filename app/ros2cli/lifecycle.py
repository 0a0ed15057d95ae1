"""`ros2 lifecycle nodes/get/list/set` (the services themselves: app.ros.lifecycle)."""

from __future__ import annotations

from typing import cast

from lifecycle_msgs.srv import GetAvailableTransitions

from app.ros.calls import call_service
from app.ros.context import CallContext
from app.ros.graph import all_nodes
from app.ros.lifecycle import (
    available_transitions,
    change_state,
    get_state,
    lifecycle_nodes,
    lifecycle_target,
)
from app.ros2cli.common import Commands, Ros2cliMessage, Verb, write_names, write_outcome
from app.ros2cli.graph_verbs import find_node
from app.ros2cli.options import (
    hidden_nodes_option,
    node_listing_options,
    node_name_argument,
    strategy,
)


def _managed(ctx: CallContext, include_hidden: bool) -> list[str]:
    """Listed nodes that serve <node>/get_state, as `ros2 lifecycle nodes` finds them."""
    listed = set(all_nodes(ctx.node, include_hidden=include_hidden))
    return sorted(n for n in lifecycle_nodes(ctx) if n in listed)


def _target(ctx: CallContext, fqn: str, include_hidden: bool) -> str:
    """A managed node's name; ros2cli says "Node not found" for any other (even a plain one)."""
    target = fqn if fqn.startswith("/") else "/" + fqn
    found = find_node(ctx, target, include_hidden, "Node not found")
    if found not in lifecycle_nodes(ctx):
        raise Ros2cliMessage("Node not found")
    return lifecycle_target(ctx, found)


def verb_nodes(ctx: CallContext, count: bool = False, all_: bool = False) -> int:
    return write_names(ctx, _managed(ctx, all_), count)


def verb_get(ctx: CallContext, fqn: str | None = None, include_hidden: bool = False) -> int:
    targets = [_target(ctx, fqn, include_hidden)] if fqn else _managed(ctx, include_hidden)
    for target in targets:
        state_id, label = get_state(ctx, target)
        ctx.write(f"{label} [{state_id}]" if fqn else f"{target}: {label} [{state_id}]")
    return 0


def verb_list(ctx: CallContext, fqn: str, include_hidden: bool = False, all_: bool = False) -> int:
    target = _target(ctx, fqn, include_hidden)
    if all_:  # every transition of the state machine, not only those from here
        response = cast(
            GetAvailableTransitions.Response,
            call_service(
                ctx,
                f"{target}/get_transition_graph",
                GetAvailableTransitions,
                GetAvailableTransitions.Request(),
            ),
        )
        rows = [
            (t.transition.label, t.transition.id, t.start_state.label, t.goal_state.label)
            for t in response.available_transitions
        ]
    else:
        rows = [(t.label, t.id, t.start, t.goal) for t in available_transitions(ctx, target)]
    for label, transition_id, start, goal in rows:
        ctx.write(f"- {label} [{transition_id}]")
        ctx.write(f"\tStart: {start}")
        ctx.write(f"\tGoal: {goal}")
    return 0


def verb_set(ctx: CallContext, fqn: str, transition: str, include_hidden: bool = False) -> int:
    """A label first, then an id, as ros2cli matches; its exit code is 0 even on failure."""
    target = _target(ctx, fqn, include_hidden)
    available = available_transitions(ctx, target)
    if not any(transition in (t.label, str(t.id)) for t in available):
        raise Ros2cliMessage(
            "Unknown transition requested, available ones are:"
            + "".join(f"\n- {t.label} [{t.id}]" for t in available)
        )
    ok, _chosen = change_state(ctx, target, transition)
    write_outcome(ctx, ok, "Transitioning successful" if ok else "Transitioning failed")
    return 0


# --- arguments: `ros2 lifecycle ...` as ros2cli takes them


def add_verbs(v: Commands, verb: Verb) -> None:
    p = verb(
        v,
        "get",
        "Get lifecycle state for one or more nodes",
        lambda c, a: verb_get(c, a.node_name, a.include_hidden_nodes),
    )
    strategy(p)
    node_name_argument(
        p,
        optional=True,
        help_text="Name of the ROS node. If no name is provided, then get the state for all nodes.",
    )
    hidden_nodes_option(p)

    p = verb(
        v,
        "list",
        "Output a list of available transitions",
        lambda c, a: verb_list(c, a.node_name, a.include_hidden_nodes, a.all),
    )
    strategy(p)
    node_name_argument(p)
    hidden_nodes_option(p)
    p.add_argument("-a", "--all", action="store_true", help="Display all existing transitions")

    p = verb(
        v,
        "nodes",
        "Output a list of nodes with lifecycle",
        lambda c, a: verb_nodes(c, a.count_nodes, a.all),
    )
    node_listing_options(p)

    p = verb(
        v,
        "set",
        "Trigger lifecycle state transition",
        lambda c, a: verb_set(c, a.node_name, a.transition, a.include_hidden_nodes),
    )
    strategy(p)
    node_name_argument(p)
    hidden_nodes_option(p)
    p.add_argument("transition", help="The lifecycle transition")
