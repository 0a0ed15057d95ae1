"""The general probes: services, topics, parameters, actions, lifecycle, logging."""

from __future__ import annotations

import random
import threading
import time
from typing import Any

from rclpy.qos import QoSProfile

from app.exercises.probes.base import (
    ProbeContext,
    draw,
    expected_value,
    random_inputs,
    same,
    values_text,
)
from app.exercises.report import Result
from app.lessons.kinds import make_kind
from app.lessons.schema import Spec
from app.ros import lifecycle, params
from app.ros.calls import GoalRun, call_service, send_goal
from app.ros.convert import fill, import_type, to_plain
from app.ros.errors import Ros2Error
from app.ros.monitor import TopicMonitor

# -- service_random ----------------------------------------------------------


def service_random(ctx: ProbeContext, p: Spec) -> Result:
    """Call a service with random inputs; compare one response field to a formula."""
    service, srv_type = p["service"], import_type(p["type"], "srv")
    name = f"service {service}"
    examples = []
    for _ in range(p.get("calls", 5)):
        values = random_inputs(ctx.rng, p["inputs"])
        request = fill(srv_type.Request, values)
        try:
            response = call_service(ctx.call, service, srv_type, request, timeout=3.0)
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


# -- topic_feed --------------------------------------------------------------


def topic_feed(ctx: ProbeContext, p: Spec) -> Result:
    """Publish ``count`` values drawn from ``inputs``; compare the node's outputs to a formula.

    ``expect`` is a formula over ``values`` (the drawn list) giving the list
    of outputs, e.g. the running sums ``[sum(values[: i + 1]) for i in range(len(values))]``.
    """
    node = ctx.call.node
    in_topic, out_topic = p["publish"], p["output"]
    name = f"feed {in_topic} -> {out_topic}"
    in_type, out_type = import_type(p["type"], "msg"), import_type(p["output_type"], "msg")
    count = int(draw(ctx.rng, p["count"]))
    inputs = [draw(ctx.rng, p["inputs"]) for _ in range(count)]
    want = list(expected_value(p["expect"], {"values": inputs}))
    publisher = node.create_publisher(in_type, in_topic, QoSProfile(depth=50))
    monitor = TopicMonitor(node, out_topic, out_type, keep=200, qos=50)
    try:
        deadline = time.monotonic() + 5.0
        while publisher.get_subscription_count() == 0:
            if time.monotonic() > deadline:
                return Result(name, False, f"nothing subscribes to {in_topic}")
            ctx.call.sleep(0.05)
        ctx.call.sleep(0.3)  # let the learner's publisher match our reader too
        before = monitor.count
        for value in inputs:
            publisher.publish(fill(in_type, {p["input_field"]: value}))
            ctx.call.sleep(p.get("period", 0.15))
        monitor.wait_for_count(before + len(want), p.get("settle", 2.0))
        field = p["field"]
        got = [to_plain(getattr(msg, field)) for _, msg in monitor.messages_since(before)]
        if len(got) < len(want):
            return Result(
                name,
                False,
                f"published {inputs} on {in_topic}; {out_topic} gave {got}, expected {want}",
            )
        tail = got[-len(want) :]
        tolerance = p.get("tolerance", 1e-6)
        wrong = [
            i for i, (a, b) in enumerate(zip(tail, want, strict=True)) if not same(a, b, tolerance)
        ]
        if not wrong:
            return Result(name, True, f"published {inputs}; {out_topic} gave {tail}")
        return Result(
            name,
            False,
            f"published {inputs} on {in_topic}; {out_topic} gave {tail}, expected {want} "
            f"(first difference at message {wrong[0] + 1}: {tail[wrong[0]]!r}, "
            f"expected {want[wrong[0]]!r})",
        )
    finally:
        monitor.close()
        node.destroy_publisher(publisher)


# -- param_set ---------------------------------------------------------------


def param_set(ctx: ProbeContext, p: Spec) -> Result:
    """Set a parameter; expect it accepted (and its effect seen) or refused with a reason."""
    target, pname, value = p.get("node", ctx.learner_node), p["name"], draw(ctx.rng, p["value"])
    name = f"parameter {pname}={value!r}"
    try:
        ok, reason = params.set_value(ctx.call, target, pname, value)
    except Ros2Error as exc:
        return Result(name, False, str(exc))
    if not p["accept"]:
        if ok:
            return Result(name, False, f"{target} accepted {pname}={value!r}; it should refuse it")
        if not reason.strip():
            return Result(name, False, f"{target} refused {pname}={value!r} but gave no reason")
        needed = p.get("reason_contains", "")
        if needed and needed.lower() not in reason.lower():
            return Result(
                name, False, f"refused with reason {reason!r}; it should mention {needed!r}"
            )
        return Result(name, True, f"refused, with the reason {reason!r}")
    if not ok:
        return Result(name, False, f"{target} refused {pname}={value!r}: {reason or 'no reason'}")
    then = p.get("then")
    if then is None:
        return Result(name, True, f"{target} accepted {pname}={value!r}")
    check = without_kind(then)
    if "expect_hz" in check:
        # A rate that follows the drawn value: the window is derived from it.
        hz = float(expected_value(check.pop("expect_hz"), {"value": value}))
        spread = float(check.pop("rate_tolerance", 0.1))
        check["min_hz"], check["max_hz"] = round(hz * (1 - spread), 3), round(hz * (1 + spread), 3)
        check.setdefault("samples", max(8, round(hz * RATE_JUDGED_SEC)))
    passed, detail = ctx.wait_check(Spec(then["kind"], check), p.get("within", 10.0))
    verdict = "then " + detail
    return Result(name, passed, f"accepted; {verdict}")


def without_kind(table: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in table.items() if k != "kind"}


# -- action_goal -------------------------------------------------------------


def action_goal(ctx: ProbeContext, p: Spec) -> Result:
    """Send a goal (and maybe cancel it); judge status, feedback and result."""
    action, type_text = p["action"], p["type"]
    goal_values = {k: draw(ctx.rng, v) for k, v in p["goal"].items()}
    goal = fill(import_type(type_text, "action").Goal, goal_values)
    cancel_after = draw(ctx.rng, p.get("cancel_after_feedback"))
    run = GoalRun(action, type_text, goal)
    name = f"action {action}" + (" (cancel)" if cancel_after else "")

    def on_feedback(_msg: Any) -> None:
        if cancel_after and len(run.feedback) == cancel_after:
            run.cancel()

    try:
        send_goal(ctx.call, run, on_feedback)
    except Ros2Error as exc:
        return Result(name, False, str(exc))
    status = run.status.lower()
    want = "canceled" if cancel_after else p.get("status", "succeeded")
    goal_text = values_text(goal_values)
    if status != want:
        return Result(name, False, f"goal {goal_text}: the action {status}, expected {want}")
    need = p.get("min_feedback", 0)
    if len(run.feedback) < need:
        return Result(
            name,
            False,
            f"goal {goal_text}: {len(run.feedback)} feedback messages, expected at least {need}",
        )
    if "result_field" in p.fields and not cancel_after:
        got = to_plain(getattr(run.result, p["result_field"]))
        want_value = expected_value(p["result_expect"], goal_values)
        if not same(got, want_value, 1e-6):
            return Result(
                name,
                False,
                f"goal {goal_text}: result {p['result_field']}={got!r}; expected {want_value!r}",
            )
    return Result(name, True, f"goal {goal_text}: {status}, {len(run.feedback)} feedback messages")


# -- lifecycle_sequence ------------------------------------------------------


def lifecycle_sequence(ctx: ProbeContext, p: Spec) -> Result:
    """Drive transitions in order; an invalid one must be refused, states must follow.

    With ``topic``, also judge "publishes only while active": messages flow
    after activate and stop after deactivate.
    """
    target = p.get("node", ctx.learner_node)
    name = f"lifecycle {target}"
    monitor = None
    if "topic" in p.fields:
        monitor = TopicMonitor(ctx.call.node, p["topic"], import_type(p["type"], "msg"), qos=10)
    done: list[str] = []
    if "walk" in p.fields:
        steps = lifecycle_walk(ctx.rng, int(draw(ctx.rng, p["walk"])), p.get("end", "active"))
    elif "steps" in p.fields:
        steps = p["steps"]
    else:
        raise ValueError("a lifecycle_sequence probe needs 'walk' (random) or 'steps'")
    try:
        for step in steps:
            transition, should_succeed = step["transition"], step.get("succeeds", True)
            try:
                ok, _info = lifecycle.change_state(ctx.call, target, transition)
            except Ros2Error as exc:
                ok, why = False, str(exc)
            else:
                why = "the node's callback returned failure"
            if ok != should_succeed:
                said = "succeeded" if ok else f"failed ({why})"
                return Result(
                    name,
                    False,
                    f"after {done or ['start']}: '{transition}' {said}, expected the opposite",
                )
            state = lifecycle.get_state(ctx.call, target)[1]
            if "state" in step and state != step["state"]:
                return Result(
                    name,
                    False,
                    f"after '{transition}' the node is {state}, expected {step['state']}",
                )
            done.append(transition if ok else f"{transition} (refused)")
            if monitor is not None and (ok or step is steps[-1]):
                verdict = _publishing_verdict(ctx, monitor, state, p["topic"])
                if verdict:
                    return Result(name, False, f"after '{transition}' ({state}): {verdict}")
        return Result(name, True, f"transitions {done} behaved, states as expected")
    finally:
        if monitor is not None:
            monitor.close()


_VALID_TRANSITIONS = {
    "unconfigured": {"configure": "inactive"},
    "inactive": {"activate": "active", "cleanup": "unconfigured"},
    "active": {"deactivate": "inactive"},
}
_TRANSITIONS = ("configure", "activate", "deactivate", "cleanup")
RATE_JUDGED_SEC = 4.0  # a rate that follows a drawn value is judged on this long of messages
INVALID_SHARE = 0.3  # of a walk's requests, about this many are invalid from the state


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


def lifecycle_walk(rng: random.Random, length: int, end: str = "active") -> list[dict[str, Any]]:
    """A random order of lifecycle requests from unconfigured, invalid ones among them.

    Every walk has at least two invalid requests, reaches active, has a
    cleanup later followed by a configure, and ends in ``end``.
    """
    if end not in _VALID_TRANSITIONS:
        raise ValueError(f"end must be one of {sorted(_VALID_TRANSITIONS)}, not {end!r}")
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
        if refused >= 2 and cleaned and any(s["state"] == "active" for s in steps):
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


# -- log_rate ----------------------------------------------------------------

LOG_RATE_MIN_LINES = 6  # fewer is no rate to judge on


def log_rate(ctx: ProbeContext, p: Spec) -> Result:
    """Count the node's /rosout records over a window: how often does it log?"""
    from rcl_interfaces.msg import Log

    target = p.get("node", ctx.learner_node)
    logger = target.lstrip("/").replace("/", ".")
    text = p.get("text", "")
    stamps: list[float] = []
    lock = threading.Lock()

    def on_log(record: Log) -> None:
        if record.name == logger and text in record.msg:
            with lock:
                stamps.append(record.stamp.sec + record.stamp.nanosec * 1e-9)

    node = ctx.call.node
    sub = node.create_subscription(Log, "/rosout", on_log, 100)
    try:
        ctx.call.sleep(p.get("window", 5.0))
    finally:
        node.destroy_subscription(sub)
    name = f"log rate of {target}"
    with lock:
        got = sorted(stamps)
    what = f"lines containing {text!r}" if text else "log lines"
    if len(got) < LOG_RATE_MIN_LINES or got[-1] <= got[0]:
        return Result(name, False, f"{len(got)} {what} from {target} in {p.get('window', 5.0):g} s")
    # By the node's own log stamps (its clock), so late delivery does not bend the rate.
    rate = (len(got) - 1) / (got[-1] - got[0])
    measured = f"{rate:.2f} Hz over {len(got)} lines (the node's log stamps)"
    if p["min_hz"] <= rate <= p["max_hz"]:
        return Result(name, True, f"{target} logs {what} at {measured}")
    return Result(
        name,
        False,
        f"{target} logs {what} at {measured}; expected {p['min_hz']}-{p['max_hz']} Hz",
    )


# Each kind's fields (the loader validates against them) and its code.
KINDS = {
    "service_random": make_kind("service type inputs field expect", "calls tolerance"),
    "topic_feed": make_kind(
        "publish type input_field inputs count output output_type field expect",
        "period settle tolerance",
    ),
    "param_set": make_kind("name value accept", "node reason_contains then within"),
    "action_goal": make_kind(
        "action type goal", "status min_feedback result_field result_expect cancel_after_feedback"
    ),
    "lifecycle_sequence": make_kind("", "steps walk end node topic type"),
    "log_rate": make_kind("min_hz max_hz", "node text window"),
}
PROBES = {
    "service_random": service_random,
    "topic_feed": topic_feed,
    "param_set": param_set,
    "action_goal": action_goal,
    "lifecycle_sequence": lifecycle_sequence,
    "log_rate": log_rate,
}
