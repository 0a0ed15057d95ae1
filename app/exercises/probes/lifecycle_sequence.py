"""Probe ``lifecycle_sequence``: drive transitions in a random order (invalid ones among them);
the refused ones must be refused, the states must follow, and with ``topic`` the node
publishes only while active.
"""

from __future__ import annotations

import random
from typing import TypedDict

from app.exercises.probes.base import ProbeContext, draw, register_probe
from app.exercises.report import Result
from app.exercises.trace import Trace
from app.lessons.schema import Spec
from app.ros import lifecycle
from app.ros.convert import import_type
from app.ros.errors import Ros2Error
from app.ros.monitor import TopicMonitor

_VALID_TRANSITIONS = {
    "unconfigured": {"configure": "inactive"},
    "inactive": {"activate": "active", "cleanup": "unconfigured"},
    "active": {"deactivate": "inactive"},
}
_TRANSITIONS = ("configure", "activate", "deactivate", "cleanup")
INVALID_SHARE = 0.3  # of a walk's requests, about this many are invalid from the state
STATES = ("unconfigured", "inactive", "active")  # the plot's levels, bottom to top


class _Request(TypedDict):
    transition: str  # the transition asked for
    state: str  # the state the node is in after it


class WalkStep(_Request, total=False):
    """One request of a drawn walk, as a step of ``steps`` is written."""

    succeeds: bool  # False for a request the state machine refuses; left out when it succeeds


@register_probe(
    "lifecycle_sequence",
    required="",
    optional="steps walk end node topic type",
    words="drives the node's lifecycle through a random order of transitions, invalid ones "
    "among them: each must succeed or be refused as the state machine says, and with a "
    "topic the node must publish only while active",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    target = p.get("node", ctx.learner_node)
    name = f"lifecycle {target}"
    monitor = None
    if "topic" in p.fields:
        monitor = TopicMonitor(ctx.call.node, p["topic"], import_type(p["type"], "msg"), qos=10)
    done: list[str] = []
    if "walk" in p.fields:
        length, end = int(draw(ctx.rng, p["walk"])), p.get("end", "active")
        steps = lifecycle_walk(ctx.rng, length, end, avoid=ctx.example.get("transitions"))
    elif "steps" in p.fields:
        steps = p["steps"]
    else:
        raise ValueError("a lifecycle_sequence probe needs 'walk' (random) or 'steps'")
    got: list[tuple[float, float]] = [(0.0, 0.0)]  # (request number, state) to plot
    wanted: list[float] = [0.0]

    def plotted(why: str = "") -> tuple[Trace, ...]:
        return (
            Trace.of(
                f"state of {target} after each lifecycle request",
                "state",
                got,
                broken_at=got[-1][0] if why else None,
                broken_why=why,
                along="request",
                levels=STATES,
                expected=wanted,
            ),
        )

    def seen(number: int, state: str, expected: str | None) -> None:
        got.append((float(number), float(STATES.index(state)) if state in STATES else -1.0))
        wanted.append(float(STATES.index(expected)) if expected in STATES else got[-1][1])

    try:
        for number, step in enumerate(steps, start=1):
            transition, should_succeed = step["transition"], step.get("succeeds", True)
            try:
                ok, _info = lifecycle.change_state(ctx.call, target, transition)
            except Ros2Error as exc:
                ok, why = False, str(exc)
            else:
                why = "the node's callback returned failure"
            if ok != should_succeed:
                said = "succeeded" if ok else f"failed ({why})"
                state = _state_or_blank(ctx, target)
                seen(number, state, step.get("state"))
                return Result(
                    name,
                    False,
                    f"after {done or ['start']}: '{transition}' {said}, expected the opposite",
                    plotted(f"'{transition}' {'succeeded' if ok else 'failed'}"),
                )
            state = lifecycle.get_state(ctx.call, target)[1]
            seen(number, state, step.get("state"))
            if "state" in step and state != step["state"]:
                return Result(
                    name,
                    False,
                    f"after '{transition}' the node is {state}, expected {step['state']}",
                    plotted(f"{state}, not {step['state']}"),
                )
            done.append(transition if ok else f"{transition} (refused)")
            if monitor is not None and (ok or step is steps[-1]):
                verdict = _publishing_verdict(ctx, monitor, state, p["topic"])
                if verdict:
                    return Result(
                        name,
                        False,
                        f"after '{transition}' ({state}): {verdict}",
                        plotted("published wrongly" if "messages" in verdict else "silent"),
                    )
        return Result(name, True, f"transitions {done} behaved, states as expected", plotted())
    finally:
        if monitor is not None:
            monitor.close()


def _state_or_blank(ctx: ProbeContext, target: str) -> str:
    try:
        return lifecycle.get_state(ctx.call, target)[1]
    except Ros2Error:
        return ""


def _path(start: str, end: str) -> list[tuple[str, str]]:
    """The shortest list of (transition, state) from ``start`` to ``end``."""
    paths: dict[str, list[tuple[str, str]]] = {start: []}
    frontier = [start]
    while frontier:
        state = frontier.pop(0)
        for transition, after in sorted(_VALID_TRANSITIONS[state].items()):
            if after not in paths:
                paths[after] = [*paths[state], (transition, after)]
                frontier.append(after)
    return paths[end]


def lifecycle_walk(
    rng: random.Random, length: int, end: str = "active", avoid: list[str] | None = None
) -> list[WalkStep]:
    """A random order of lifecycle requests from unconfigured, invalid ones among them.

    Every walk has at least two invalid requests, reaches active, has a
    cleanup later followed by a configure, and ends in ``end``. Its accepted
    transitions are never ``avoid`` (the statement's example order): a node
    that replays the example must not pass by luck.
    """
    if end not in _VALID_TRANSITIONS:
        raise ValueError(f"end must be one of {sorted(_VALID_TRANSITIONS)}, not {end!r}")
    steps: list[WalkStep]
    for _ in range(500):
        state, steps = "unconfigured", []
        for _ in range(length):
            valid = _VALID_TRANSITIONS[state]
            if rng.random() < INVALID_SHARE:
                invalid = [t for t in _TRANSITIONS if t not in valid]
                steps.append({"transition": rng.choice(invalid), "succeeds": False, "state": state})
                continue
            transition = rng.choice(sorted(valid))
            state = valid[transition]
            steps.append({"transition": transition, "state": state})
        for transition, after in _path(state, end):
            steps.append({"transition": transition, "state": after})
        labels = [s["transition"] for s in steps if s.get("succeeds", True)]
        refused = sum(not s.get("succeeds", True) for s in steps)
        cleaned = "cleanup" in labels and "configure" in labels[labels.index("cleanup") :]
        shown = avoid is not None and labels == list(avoid)
        if refused >= 2 and cleaned and any(s["state"] == "active" for s in steps) and not shown:
            return steps
    raise ValueError(f"no lifecycle walk of {length} steps meets the rules; use at least 6")


def _publishing_verdict(ctx: ProbeContext, monitor: TopicMonitor, state: str, topic: str) -> str:
    """'' when the node publishes exactly while active, else what went wrong."""
    before = monitor.count
    ctx.call.sleep(1.5)
    fresh = monitor.count - before
    if state == "active" and fresh == 0:
        return f"nothing on {topic} in 1.5 s while active"
    if state != "active" and fresh > 0:
        return f"{fresh} messages on {topic} in 1.5 s while {state}; publish only while active"
    return ""
