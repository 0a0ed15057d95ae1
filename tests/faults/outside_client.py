"""A plain rclpy program from outside the project that sends hostile requests to running nodes.

It stands for any client on the ROS graph (a learner's script, a buggy tool):
it imports rclpy and interface packages only, never the project's code, finds
what each node offers from the graph and calls it with out-of-range,
wrong-typed, empty and huge values. Every call must get an answer or a
refusal within CALL_TIMEOUT seconds; anything else is listed as a problem.

    outside_client.py lifecycle /lifecycle_talker
    outside_client.py fuzz /node_a /node_b ... [--expect-service S] [--expect-action A]

Prints one JSON object on stdout: ``calls`` (one record per call),
``problems`` (what went wrong, empty when all is well) and ``counts``.
Exit status 0 when the report was written, whatever it says.
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import os
import sys
import threading
import time
import uuid
from collections import Counter
from typing import Any

import rclpy
from action_msgs.msg import GoalInfo, GoalStatus
from action_msgs.srv import CancelGoal
from builtin_interfaces.msg import Time
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetAvailableTransitions, GetState
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import (
    DescribeParameters,
    GetParameters,
    GetParameterTypes,
    ListParameters,
    SetParameters,
    SetParametersAtomically,
)
from rclpy.action import ActionClient
from rclpy.action.graph import get_action_server_names_and_types_by_node
from rclpy.client import Client
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.task import Future
from tutorial_interfaces.action import Fibonacci
from tutorial_interfaces.srv import AddTwoInts
from unique_identifier_msgs.msg import UUID

CALL_TIMEOUT = 8.0  # generous: two cores shared by twenty processes
DISCOVERY_TIMEOUT = 45.0
DWELL = 0.6  # seconds a round of hostile parameter values stays in effect
INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1
MEGABYTE = "x" * 2**20
PARAMETER_SERVICES: dict[str, type] = {
    "describe_parameters": DescribeParameters,
    "get_parameter_types": GetParameterTypes,
    "get_parameters": GetParameters,
    "list_parameters": ListParameters,
    "set_parameters": SetParameters,
    "set_parameters_atomically": SetParametersAtomically,
}

# A value of each ParameterType, to send where another type is expected.
SAMPLES: dict[int, dict[str, Any]] = {
    ParameterType.PARAMETER_BOOL: {"bool_value": True},
    ParameterType.PARAMETER_INTEGER: {"integer_value": INT64_MAX},
    ParameterType.PARAMETER_DOUBLE: {"double_value": math.nan},
    ParameterType.PARAMETER_STRING: {"string_value": "💥" * 100},
    ParameterType.PARAMETER_BYTE_ARRAY: {"byte_array_value": [b"\x00", b"\xff"] * 500},
    ParameterType.PARAMETER_BOOL_ARRAY: {"bool_array_value": [True] * 1000},
    ParameterType.PARAMETER_INTEGER_ARRAY: {"integer_array_value": [INT64_MIN] * 1000},
    ParameterType.PARAMETER_DOUBLE_ARRAY: {"double_array_value": [math.inf, math.nan]},
    ParameterType.PARAMETER_STRING_ARRAY: {"string_array_value": ["", "a" * 1000]},
}
UNKNOWN_TYPES = (10, 99, 255)  # not ParameterType values at all
# Values of the right type that a node may not cope with, sent in rounds.
HOSTILE: dict[int, list[dict[str, Any]]] = {
    ParameterType.PARAMETER_DOUBLE: [
        {"double_value": v}
        for v in (math.nan, math.inf, -math.inf, 0.0, -1.0, 1e308, -1e308, 5e-324)
    ],
    ParameterType.PARAMETER_INTEGER: [
        {"integer_value": v} for v in (0, -1, INT64_MAX, INT64_MIN)
    ],
    ParameterType.PARAMETER_STRING: [
        {"string_value": v}
        for v in ("", MEGABYTE, "\u202e💥 $(reboot) ../../etc/passwd", " ")
    ],
    ParameterType.PARAMETER_BYTE_ARRAY: [{"byte_array_value": []}],
    ParameterType.PARAMETER_BOOL_ARRAY: [{"bool_array_value": []}],
    ParameterType.PARAMETER_INTEGER_ARRAY: [
        {"integer_array_value": []},
        {"integer_array_value": [INT64_MAX] * 100_000},
    ],
    ParameterType.PARAMETER_DOUBLE_ARRAY: [
        {"double_array_value": []},
        {"double_array_value": [math.nan] * 100_000},
    ],
    ParameterType.PARAMETER_STRING_ARRAY: [
        {"string_array_value": []},
        {"string_array_value": [MEGABYTE]},
    ],
}  # fmt: skip
BAD_NAMES = [
    "", " ", "bad name!", "a..b", "/absolute", "~private", "1nvalid", "💥", "x" * 10_000,
    "use_sim_time ", "USE_SIM_TIME", "a.b.c.d.e.f", "\u202e", "$(reboot)",
]  # fmt: skip

# The lifecycle transitions valid from each primary state (design of managed nodes).
VALID_FROM = {
    "unconfigured": {Transition.TRANSITION_CONFIGURE, Transition.TRANSITION_UNCONFIGURED_SHUTDOWN},
    "inactive": {
        Transition.TRANSITION_CLEANUP,
        Transition.TRANSITION_ACTIVATE,
        Transition.TRANSITION_INACTIVE_SHUTDOWN,
    },
    "active": {Transition.TRANSITION_DEACTIVATE, Transition.TRANSITION_ACTIVE_SHUTDOWN},
    "finalized": set(),
}
LABELS = ("configure", "cleanup", "activate", "deactivate", "shutdown")
VALID_LABELS = {
    "unconfigured": {"configure", "shutdown"},
    "inactive": {"cleanup", "activate", "shutdown"},
    "active": {"deactivate", "shutdown"},
    "finalized": set(),
}
BOGUS_LABELS = ["bogus", "CONFIGURE", " configure", "configure ", "💥", "x" * 65_536, "transition"]


def any_answer(_response: Any) -> tuple[str, str]:
    return "answered", ""


def describe_value(fields: dict[str, Any]) -> str:
    text = repr(fields)
    return text if len(text) <= 70 else f"{text[:60]}... ({len(text)} chars)"


class Report:
    def __init__(self) -> None:
        self.calls: list[dict[str, Any]] = []
        self.problems: list[str] = []
        self.accepted: list[str] = []  # hostile parameter values a node took (not an error)

    def add(
        self,
        target: str,
        case: str,
        outcome: str,
        detail: str = "",
        seconds: float = 0.0,
        values: int = 1,
    ) -> None:
        """One call; ``values``: how many inputs it carried (parameters in one request)."""
        self.calls.append(
            {
                "target": target,
                "case": case[:120],
                "outcome": outcome,
                "detail": detail[:300],
                "seconds": round(seconds, 4),
                "values": values,
            }
        )
        if outcome in ("timeout", "wrong"):
            self.problems.append(f"{target} [{case[:120]}]: {outcome} {detail[:300]}")

    def dump(self) -> str:
        counts = Counter(c["outcome"] for c in self.calls)
        return json.dumps(
            {
                "calls": self.calls,
                "problems": self.problems,
                "counts": dict(counts),
                "values": sum(c["values"] for c in self.calls if c["outcome"] != "info"),
                "accepted": self.accepted,
                "slowest": max((c["seconds"] for c in self.calls), default=0.0),
            }
        )


class OutsideClient(Node):
    def __init__(self) -> None:
        super().__init__(
            f"outside_client_{uuid.uuid4().hex[:8]}",
            start_parameter_services=False,
            enable_rosout=False,
        )
        self.report = Report()
        self.clients_by_name: dict[tuple[str, type], Client] = {}
        self.dead: set[str] = set()  # node names that stopped answering
        # One executor for the whole run (rclpy.spin_* would add and remove the node each time).
        self.spinner = SingleThreadedExecutor(context=self.context)
        self.spinner.add_node(self)

    # -- plumbing --------------------------------------------------------------

    def client(self, srv_type: type, name: str) -> Client:
        key = (name, srv_type)
        if key not in self.clients_by_name:
            self.clients_by_name[key] = self.create_client(srv_type, name)
        return self.clients_by_name[key]

    def wait(self, future: Future, timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        while not future.done() and time.monotonic() < deadline:
            self.spinner.spin_once(timeout_sec=min(0.1, max(0.0, deadline - time.monotonic())))
        # A completed future schedules its done-callbacks as executor tasks; run them now,
        # or they pile up and every later spin gets slower (seen with rclpy 7.1.6).
        for _ in range(4):
            self.spinner.spin_once(timeout_sec=0.0)
        return future.done()

    def wait_ready(self, clients: list[Client], timeout: float = DISCOVERY_TIMEOUT) -> list[str]:
        deadline = time.monotonic() + timeout
        waiting = list(clients)
        while waiting and time.monotonic() < deadline:
            waiting = [c for c in waiting if not c.service_is_ready()]
            self.spinner.spin_once(timeout_sec=0.05)
        return [c.srv_name for c in waiting]

    def call(self, srv_type: type, name: str, request: Any, owner: str) -> tuple[Any, float]:
        """The response (None on timeout) and the seconds it took; a timeout marks owner dead."""
        if owner in self.dead:
            return None, 0.0
        client = self.client(srv_type, name)
        started = time.monotonic()
        future = client.call_async(request)
        if not self.wait(future, CALL_TIMEOUT):
            client.remove_pending_request(future)
            self.dead.add(owner)
            return None, time.monotonic() - started
        return future.result(), time.monotonic() - started

    def expect(
        self,
        target: str,
        case: str,
        srv_type: type,
        request: Any,
        owner: str,
        judge,
        values: int = 1,
    ) -> Any:
        """Call, then ``judge(response) -> (outcome, detail)``: answered, refused or wrong."""
        if owner in self.dead:
            self.report.add(target, case, "skipped", f"{owner} stopped answering earlier")
            return None
        response, seconds = self.call(srv_type, target, request, owner)
        if response is None:
            detail = f"no answer in {CALL_TIMEOUT} s"
            self.report.add(target, case, "timeout", detail, seconds, values)
            return None
        outcome, detail = judge(response)
        self.report.add(target, case, outcome, detail, seconds, values)
        return response

    # -- lifecycle -------------------------------------------------------------

    def get_state(self, node: str) -> str | None:
        response, _ = self.call(GetState, f"{node}/get_state", GetState.Request(), node)
        return None if response is None else response.current_state.label

    def change(self, node: str, case: str, transition: Transition, expect_success: bool) -> bool:
        before = self.get_state(node)
        request = ChangeState.Request(transition=transition)

        def judge(response) -> tuple[str, str]:
            if response.success != expect_success:
                return "wrong", f"success={response.success} from {before!r}"
            return ("answered" if expect_success else "refused"), f"from {before!r}"

        response = self.expect(f"{node}/change_state", case, ChangeState, request, node, judge)
        if response is None:
            return False
        if not expect_success:
            after = self.get_state(node)
            if after != before:
                self.report.add(
                    f"{node}/change_state", case, "wrong", f"state {before!r} -> {after!r}"
                )
        return bool(response.success)

    def check_available(self, node: str, state: str) -> None:
        def judge(response) -> tuple[str, str]:
            ids = {t.transition.id for t in response.available_transitions}
            if ids != VALID_FROM[state]:
                return "wrong", f"available {sorted(ids)} in {state}"
            return "answered", f"{sorted(ids)}"

        self.expect(
            f"{node}/get_available_transitions",
            f"in {state}",
            GetAvailableTransitions,
            GetAvailableTransitions.Request(),
            node,
            judge,
        )

    def fuzz_lifecycle_state(self, node: str, state: str) -> None:
        actual = self.get_state(node)
        if actual != state:
            self.report.add(f"{node}/get_state", f"expected {state}", "wrong", f"is {actual!r}")
            return
        self.check_available(node, state)
        for tid in range(256):
            if tid not in VALID_FROM[state]:
                self.change(node, f"{state}: id {tid}", Transition(id=tid), expect_success=False)
        bogus = BOGUS_LABELS + [label for label in LABELS if label not in VALID_LABELS[state]]
        for label in bogus:
            for tid in (0, *sorted(VALID_FROM[state])[:1]):  # the label wins over a valid id
                self.change(
                    node,
                    f"{state}: label {label[:20]!r} id {tid}",
                    Transition(id=tid, label=label),
                    expect_success=False,
                )
        if self.get_state(node) != state:
            self.report.add(f"{node}/get_state", f"still {state}", "wrong", "state moved")

    def run_lifecycle(self, node: str) -> None:
        clients = [
            self.client(ChangeState, f"{node}/change_state"),
            self.client(GetState, f"{node}/get_state"),
            self.client(GetAvailableTransitions, f"{node}/get_available_transitions"),
        ]
        missing = self.wait_ready(clients)
        if missing:
            self.report.add(node, "discovery", "timeout", f"services not found: {missing}")
            return
        T = Transition
        # Through every primary state, fuzzing each on the first visit; valid transitions
        # go by id or by label and must still work after all the refusals.
        steps: list[tuple[str | None, Transition | None]] = [
            ("unconfigured", T(id=T.TRANSITION_CONFIGURE)),
            ("inactive", T(id=T.TRANSITION_ACTIVATE)),
            ("active", T(label="deactivate")),
            (None, T(id=T.TRANSITION_CLEANUP)),
            (None, T(label="configure")),
            (None, T(id=T.TRANSITION_ACTIVATE)),
            (None, T(id=T.TRANSITION_ACTIVE_SHUTDOWN)),
            ("finalized", None),
        ]
        for fuzz_state, transition in steps:
            if fuzz_state is not None:
                self.fuzz_lifecycle_state(node, fuzz_state)
            if transition is not None:
                name = transition.label or f"id {transition.id}"
                self.change(node, f"valid: {name}", transition, expect_success=True)
        final = self.get_state(node)
        if final != "finalized":
            self.report.add(f"{node}/get_state", "at the end", "wrong", f"is {final!r}")

    # -- discovery -------------------------------------------------------------

    def wait_for_nodes(self, nodes: list[str], expect_services: list[str]) -> None:
        deadline = time.monotonic() + DISCOVERY_TIMEOUT
        while time.monotonic() < deadline:
            seen = {f"{ns.rstrip('/')}/{n}" for n, ns in self.get_node_names_and_namespaces()}
            services = {name for name, _types in self.get_service_names_and_types()}
            if set(nodes) <= seen and set(expect_services) <= services:
                return
            self.spinner.spin_once(timeout_sec=0.1)
        self.report.add("graph", "discovery", "timeout", f"missing nodes or services: {nodes}")

    def interfaces_of(self, node: str) -> tuple[dict[str, str], dict[str, str]]:
        ns, _, name = node.rpartition("/")
        services = {
            srv: types[0]
            for srv, types in self.get_service_names_and_types_by_node(name, ns or "/")
            if "/_action/" not in srv
        }
        actions = {
            action: types[0]
            for action, types in get_action_server_names_and_types_by_node(self, name, ns or "/")
        }
        return services, actions

    # -- parameters ------------------------------------------------------------

    def fuzz_parameters(self, nodes: list[str]) -> None:
        declared: dict[str, dict[str, tuple[int, bool, ParameterValue]]] = {}
        ready = [self.client(t, f"{n}/{s}") for n in nodes for s, t in PARAMETER_SERVICES.items()]
        missing = self.wait_ready(ready)
        for name in missing:
            self.report.add(name, "discovery", "timeout", "parameter service not found")
        for node in nodes:
            declared[node] = self.read_parameters(node)
        for node in nodes:
            self.query_parameters(node, list(declared[node]))
            self.refuse_wrong_types(node, declared[node])
        rounds = max(len(v) for v in HOSTILE.values())
        for index in range(rounds):
            for node in nodes:
                self.hostile_round(node, declared[node], index)
            time.sleep(DWELL)  # let timers and callbacks run with these values
        for node in nodes:
            self.restore(node, declared[node])

    def read_parameters(self, node: str) -> dict[str, tuple[int, bool, ParameterValue]]:
        listed = self.expect(
            f"{node}/list_parameters",
            "all",
            ListParameters,
            ListParameters.Request(),
            node,
            lambda r: ("answered", f"{len(r.result.names)} names"),
        )
        if listed is None:
            return {}
        names = list(listed.result.names)
        answers = {}
        fields = (("get_parameters", "values"), ("describe_parameters", "descriptors"))
        for service, field in fields:
            srv_type = PARAMETER_SERVICES[service]
            answers[field] = self.expect(
                f"{node}/{service}", "all declared", srv_type, srv_type.Request(names=names), node,
                lambda r, field=field: ("answered", "") if len(getattr(r, field)) == len(names)
                else ("wrong", f"{len(getattr(r, field))} {field} for {len(names)} names"),
            )  # fmt: skip
        values, descriptors = answers["values"], answers["descriptors"]
        if values is None or descriptors is None:
            return {}
        return {
            name: (value.type, descriptor.read_only, value)
            for name, value, descriptor in zip(
                names, values.values, descriptors.descriptors, strict=True
            )
        }

    def query_parameters(self, node: str, names: list[str]) -> None:
        many = [f"p{i}" for i in range(5000)]
        for case, query in (
            ("no names", []),
            ("bad names", BAD_NAMES),
            ("5000 unknown names", many),
            ("declared and bad", names + BAD_NAMES),
        ):
            for service in ("get_parameters", "describe_parameters", "get_parameter_types"):
                srv_type = PARAMETER_SERVICES[service]
                request = srv_type.Request(names=query)
                self.expect(f"{node}/{service}", case, srv_type, request, node, any_answer)
        for prefixes, depth in (
            ([], 0), (BAD_NAMES, 1), (["x" * 100_000], 2**64 - 1), ([""], 2**64 - 1), (["."], 1),
        ):  # fmt: skip
            self.expect(
                f"{node}/list_parameters",
                f"prefixes {describe_value({'p': prefixes})} depth {depth}",
                ListParameters,
                ListParameters.Request(prefixes=prefixes, depth=depth),
                node,
                any_answer,
            )

    def set_and_judge(
        self, node: str, case: str, params: list[Parameter], expect_refused: bool
    ) -> list[bool]:
        """One SetParameters call; returns which were accepted."""
        accepted: list[bool] = []

        def judge(response) -> tuple[str, str]:
            if len(response.results) != len(params):
                return "wrong", f"{len(response.results)} results for {len(params)} parameters"
            bad = []
            for param, result in zip(params, response.results, strict=True):
                accepted.append(result.successful)
                if result.successful and not expect_refused:
                    shown = describe_value(dict(value_fields(param)))
                    self.report.accepted.append(f"{node}.{param.name}={shown}")
                if result.successful and expect_refused:
                    bad.append(f"{param.name[:30]} accepted type {param.value.type}")
                elif not result.successful and not result.reason:
                    bad.append(f"{param.name[:30]} refused without a reason")
            if bad:
                return "wrong", "; ".join(bad[:5])
            refused = accepted.count(False)
            return ("refused" if refused else "answered"), f"{refused}/{len(params)} refused"

        request = SetParameters.Request(parameters=params)
        self.expect(
            f"{node}/set_parameters", case, SetParameters, request, node, judge, len(params)
        )
        return accepted

    def refuse_wrong_types(self, node: str, declared: dict[str, tuple[int, bool, Any]]) -> None:
        for name, (ptype, _read_only, _value) in declared.items():
            wrong = [
                Parameter(name=name, value=ParameterValue(type=t, **fields))
                for t, fields in SAMPLES.items()
                if t != ptype
            ]
            wrong += [Parameter(name=name, value=ParameterValue(type=t)) for t in UNKNOWN_TYPES]
            wrong.append(Parameter(name=name, value=ParameterValue()))  # NOT_SET: undeclare
            self.set_and_judge(node, f"{name}: wrong types", wrong, expect_refused=True)
        bogus = [
            Parameter(name=bad, value=ParameterValue(type=ParameterType.PARAMETER_INTEGER))
            for bad in BAD_NAMES
        ]
        self.set_and_judge(node, "undeclared and bad names", bogus, expect_refused=True)
        self.set_and_judge(node, "empty request", [], expect_refused=False)
        mixed = [
            Parameter(name=name, value=ParameterValue(type=99)) for name in list(declared)[:1]
        ] + bogus[:3]
        for case, params in (("unknown type and bad names", mixed), ("nothing", [])):
            self.expect(
                f"{node}/set_parameters_atomically",
                case,
                SetParametersAtomically,
                SetParametersAtomically.Request(parameters=params),
                node,
                lambda r, params=params: (
                    ("answered", "empty")
                    if not params
                    else ("refused", r.result.reason[:80])
                    if not r.result.successful and r.result.reason
                    else ("wrong", f"successful={r.result.successful} reason={r.result.reason!r}")
                ),
            )

    def hostile_round(
        self, node: str, declared: dict[str, tuple[int, bool, Any]], index: int
    ) -> None:
        params = []
        for name, (ptype, _read_only, _value) in declared.items():
            choices = HOSTILE.get(ptype, [])
            if index >= len(choices):
                continue  # bools: only wrong types (use_sim_time=true would stop the clock)
            fields = choices[index]
            params.append(Parameter(name=name, value=ParameterValue(type=ptype, **fields)))
        if params:
            values = ", ".join(
                f"{p.name}={describe_value({k: v for k, v in value_fields(p)})}" for p in params[:3]
            )
            self.set_and_judge(node, f"round {index}: {values}", params, expect_refused=False)

    def restore(self, node: str, declared: dict[str, tuple[int, bool, ParameterValue]]) -> None:
        params = [
            Parameter(name=name, value=value)
            for name, (_t, read_only, value) in declared.items()
            if not read_only and value.type in HOSTILE
        ]
        if not params:
            return

        def judge(response) -> tuple[str, str]:
            refused = [p.name for p, r in zip(params, response.results, strict=True)
                       if not r.successful]  # fmt: skip
            return ("wrong", f"restore refused: {refused}") if refused else ("answered", "")

        request = SetParameters.Request(parameters=params)
        self.expect(f"{node}/set_parameters", "restore", SetParameters, request, node, judge)

    # -- services and actions ----------------------------------------------------

    def fuzz_add_two_ints(self, node: str, name: str) -> None:
        for a, b in (
            (INT64_MAX, 1), (INT64_MIN, -1), (INT64_MAX, INT64_MAX), (INT64_MIN, INT64_MIN),
            (INT64_MAX, INT64_MIN), (0, 0), (-1, INT64_MIN + 1), (2, 3),
        ):  # fmt: skip

            def judge(response, a=a, b=b) -> tuple[str, str]:
                if INT64_MIN <= a + b <= INT64_MAX and response.sum != a + b:
                    return "wrong", f"sum {response.sum}"
                return "answered", f"sum {response.sum}"

            request = AddTwoInts.Request(a=a, b=b)
            self.expect(name, f"a={a} b={b}", AddTwoInts, request, node, judge)

    def fuzz_change_state(self, node: str, name: str) -> None:
        state = self.get_state(node)
        valid_ids = VALID_FROM.get(state or "", set())
        valid_labels = VALID_LABELS.get(state or "", set())
        cases = [Transition(id=t) for t in (0, 2, 3, 4, 6, 7, 8, 10, 99, 255) if t not in valid_ids]
        cases += [Transition(label=x) for x in ("bogus", "activate", "x" * 100_000)
                  if x not in valid_labels]  # fmt: skip
        for transition in cases:
            self.change(
                node, f"id {transition.id} label {transition.label[:20]!r}", transition, False
            )

    def fuzz_type_description(self, node: str, name: str, srv_type: type) -> None:
        Request = srv_type.Request
        for case, request in (
            ("empty", Request()),
            ("unknown type", Request(type_name="no/msg/Such", type_hash="RIHS01_" + "0" * 64)),
            ("bad hash", Request(type_name="std_msgs/msg/String", type_hash="garbage",
                                 include_type_sources=True)),
            ("huge", Request(type_name="x" * 10_000, type_hash="y" * 10_000,
                             include_type_sources=True)),
        ):  # fmt: skip
            self.expect(name, case, srv_type, request, node, any_answer)

    def fuzz_default_request(self, node: str, name: str, srv_type: type) -> None:
        self.expect(name, "default request", srv_type, srv_type.Request(), node, any_answer)

    def action_goal(
        self, client: ActionClient, order: int, node: str, target: str, case: str
    ) -> Any:
        started = time.monotonic()
        future = client.send_goal_async(Fibonacci.Goal(order=order))
        if not self.wait(future, CALL_TIMEOUT):
            self.dead.add(node)
            self.report.add(target, case, "timeout", "no goal response", CALL_TIMEOUT)
            return None
        handle = future.result()
        return handle, time.monotonic() - started

    def action_result(self, handle: Any, node: str, timeout: float = 3 * CALL_TIMEOUT) -> Any:
        future = handle.get_result_async()
        if not self.wait(future, timeout):
            self.dead.add(node)
            return None
        return future.result()

    def fuzz_fibonacci(self, node: str, name: str) -> None:
        client = ActionClient(self, Fibonacci, name)
        try:
            if not client.wait_for_server(timeout_sec=DISCOVERY_TIMEOUT):
                self.report.add(name, "discovery", "timeout", "no action server")
                return
            for order in (-1, -(2**31), 2**31 - 1, 47, 10_000):
                got = self.action_goal(client, order, node, name, f"order {order}")
                if got is None:
                    return
                handle, seconds = got
                outcome = "refused" if not handle.accepted else "wrong"
                self.report.add(name, f"order {order}", outcome, "goal rejected", seconds)
            # Order 0: an empty computation, accepted and done at once.
            got = self.action_goal(client, 0, node, name, "order 0")
            if got is None:
                return
            handle, seconds = got
            result = self.action_result(handle, node) if handle.accepted else None
            ok = result is not None and list(result.result.sequence) == [0]
            self.report.add(name, "order 0", "answered" if ok else "wrong", str(result), seconds)
            # The largest order, cancelled at once; then a goal replaced by a newer one.
            got = self.action_goal(client, 46, node, name, "order 46 then cancel")
            if got is None:
                return
            handle, seconds = got
            if handle.accepted:
                cancel = handle.cancel_goal_async()
                self.wait(cancel, CALL_TIMEOUT)
                result = self.action_result(handle, node)
                status = None if result is None else result.status
                ok = status == GoalStatus.STATUS_CANCELED
                self.report.add(
                    name, "order 46 then cancel", "answered" if ok else "wrong", f"{status}"
                )
            else:
                self.report.add(name, "order 46", "wrong", "rejected")
            first = self.action_goal(client, 46, node, name, "order 46, replaced")
            second = self.action_goal(client, 2, node, name, "order 2, newest")
            if first is None or second is None:
                return
            results = [self.action_result(h, node) for h, _s in (first, second)]
            statuses = [None if r is None else r.status for r in results]
            # Newest wins: the first is aborted (the order the server saw them in decides).
            ok = sorted(statuses, key=str) == sorted(
                [GoalStatus.STATUS_ABORTED, GoalStatus.STATUS_SUCCEEDED], key=str
            )
            self.report.add(name, "two goals", "answered" if ok else "wrong", f"{statuses}")
        finally:
            client.destroy()
        self.fuzz_raw_action_services(node, name)

    def fuzz_raw_action_services(self, node: str, name: str) -> None:
        send = Fibonacci.Impl.SendGoalService
        get_result = Fibonacci.Impl.GetResultService
        known = UUID(uuid=list(uuid.uuid4().bytes))
        stranger = UUID(uuid=list(uuid.uuid4().bytes))
        for case, request, expect_accept in (
            ("raw goal order 1", send.Request(goal_id=known, goal=Fibonacci.Goal(order=1)), True),
            ("same goal id again", send.Request(goal_id=known, goal=Fibonacci.Goal(order=1)),
             False),
            ("zero goal id, order -5", send.Request(goal=Fibonacci.Goal(order=-5)), False),
        ):  # fmt: skip
            self.expect(
                f"{name}/_action/send_goal", case, send, request, node,
                lambda r, e=expect_accept: (
                    ("answered" if e else "refused", f"accepted={r.accepted}")
                    if r.accepted == e else ("wrong", f"accepted={r.accepted}")
                ),
            )  # fmt: skip
        self.goal_burst(node, name)
        self.expect(
            f"{name}/_action/get_result", "unknown goal id", get_result,
            get_result.Request(goal_id=stranger), node,
            lambda r: ("answered", f"status {r.status}") if r.status == GoalStatus.STATUS_UNKNOWN
            else ("wrong", f"status {r.status}"),
        )  # fmt: skip
        self.expect(
            f"{name}/_action/get_result", "the raw goal", get_result,
            get_result.Request(goal_id=known), node,
            lambda r: ("answered", f"status {r.status} {list(r.result.sequence)}"),
        )  # fmt: skip
        for case, info in (
            ("cancel unknown goal id", GoalInfo(goal_id=stranger)),
            ("cancel all goals (zero id, zero stamp)", GoalInfo()),
            ("cancel before a far-future stamp", GoalInfo(stamp=Time(sec=2**31 - 1))),
        ):
            self.expect(
                f"{name}/_action/cancel_goal", case, CancelGoal,
                CancelGoal.Request(goal_info=info), node,
                lambda r: ("answered", f"return_code {r.return_code}"),
            )  # fmt: skip

    def goal_burst(self, node: str, name: str, count: int = 6) -> None:
        """Goals sent all at once, without waiting: each is answered and ends (the newest wins)."""
        send = Fibonacci.Impl.SendGoalService
        get_result = Fibonacci.Impl.GetResultService
        target = f"{name}/_action/send_goal"
        ids = [UUID(uuid=list(uuid.uuid4().bytes)) for _ in range(count)]
        client = self.client(send, target)
        started = time.monotonic()
        futures = [
            client.call_async(send.Request(goal_id=goal_id, goal=Fibonacci.Goal(order=3)))
            for goal_id in ids
        ]
        for future in futures:
            if not self.wait(future, CALL_TIMEOUT):
                self.dead.add(node)
                self.report.add(target, f"burst of {count} goals", "timeout", "", CALL_TIMEOUT)
                return
        accepted = [f.result().accepted for f in futures]
        seconds = time.monotonic() - started
        outcome = "answered" if all(accepted) else "wrong"
        self.report.add(target, f"burst of {count} goals", outcome, f"{accepted}", seconds, count)
        statuses = []
        for goal_id in ids:
            response, _ = self.call(get_result, f"{name}/_action/get_result",
                                    get_result.Request(goal_id=goal_id), node)  # fmt: skip
            statuses.append(None if response is None else response.status)
        ended = (GoalStatus.STATUS_SUCCEEDED, GoalStatus.STATUS_ABORTED)
        ok = all(s in ended for s in statuses) and GoalStatus.STATUS_SUCCEEDED in statuses
        self.report.add(f"{name}/_action/get_result", f"burst of {count} goals: results",
                        "answered" if ok else "wrong", f"{statuses}", 0.0, count)  # fmt: skip

    # -- health ----------------------------------------------------------------

    def health(self, nodes: list[str], services: dict[str, dict[str, str]]) -> None:
        """After everything: every node still answers a normal request."""
        for node in nodes:
            self.dead.discard(node)  # one more chance: a slow node is not a dead one
            self.expect(
                f"{node}/get_parameters", "health: use_sim_time", GetParameters,
                GetParameters.Request(names=["use_sim_time"]), node,
                lambda r: ("answered", "") if len(r.values) == 1 else ("wrong", "no value"),
            )  # fmt: skip
            for name, type_name in services.get(node, {}).items():
                if type_name == "tutorial_interfaces/srv/AddTwoInts":
                    self.expect(
                        name, "health: 2 + 3", AddTwoInts, AddTwoInts.Request(a=2, b=3), node,
                        lambda r: ("answered", "") if r.sum == 5 else ("wrong", f"{r.sum}"),
                    )  # fmt: skip
                elif type_name == "lifecycle_msgs/srv/GetState":
                    self.expect(
                        name, "health: get_state", GetState, GetState.Request(), node,
                        lambda r: ("answered", r.current_state.label),
                    )  # fmt: skip

    def health_action(self, node: str, name: str) -> None:
        client = ActionClient(self, Fibonacci, name)
        try:
            if not client.wait_for_server(timeout_sec=CALL_TIMEOUT):
                self.report.add(name, "health: order 3", "timeout", "no action server")
                return
            got = self.action_goal(client, 3, node, name, "health: order 3")
            if got is None:
                return
            handle, seconds = got
            result = self.action_result(handle, node) if handle.accepted else None
            ok = result is not None and list(result.result.sequence) == [0, 1, 1, 2]
            self.report.add(name, "health: order 3", "answered" if ok else "wrong", str(result))
        finally:
            client.destroy()

    # -- the whole run -----------------------------------------------------------

    def run_fuzz(self, nodes: list[str], expect_services: list[str], expect_actions: list[str]):
        self.wait_for_nodes(nodes, expect_services)
        services: dict[str, dict[str, str]] = {}
        actions: dict[str, dict[str, str]] = {}
        for node in list(nodes):
            try:
                services[node], actions[node] = self.interfaces_of(node)
            except Exception as exc:  # NodeNameNonExistentError: never seen, or gone
                self.report.add(node, "discovery", "timeout", f"not in the graph: {exc}")
                nodes.remove(node)
        seen_actions = {a for per_node in actions.values() for a in per_node}
        for action in expect_actions:
            if action not in seen_actions:
                self.report.add(action, "discovery", "timeout", "action not in the graph")
        # Action goals first: the parameter rounds below may slow step_period to its edge.
        for node in nodes:
            for name, type_name in actions[node].items():
                if type_name == "tutorial_interfaces/action/Fibonacci":
                    self.fuzz_fibonacci(node, name)
        for node in nodes:
            for name, type_name in sorted(services[node].items()):
                if name.rsplit("/", 1)[-1] in PARAMETER_SERVICES:
                    continue  # below, all nodes at once
                srv_type = import_type(type_name)
                if type_name == "tutorial_interfaces/srv/AddTwoInts":
                    self.fuzz_add_two_ints(node, name)
                elif type_name == "lifecycle_msgs/srv/ChangeState":
                    self.fuzz_change_state(node, name)
                elif type_name == "type_description_interfaces/srv/GetTypeDescription":
                    self.fuzz_type_description(node, name, srv_type)
                else:
                    self.fuzz_default_request(node, name, srv_type)
        self.fuzz_parameters(nodes)
        self.health(nodes, services)
        for node in nodes:
            for name, type_name in actions[node].items():
                if type_name == "tutorial_interfaces/action/Fibonacci":
                    self.dead.discard(node)
                    self.health_action(node, name)
        self.report.calls.append(
            {"target": "graph", "case": "interfaces", "outcome": "info",
             "detail": json.dumps({"services": services, "actions": actions}), "seconds": 0}
        )  # fmt: skip


def value_fields(param: Parameter) -> list[tuple[str, Any]]:
    """The field of ``param.value`` that its type uses, for a readable case name."""
    fields = {
        ParameterType.PARAMETER_BOOL: "bool_value",
        ParameterType.PARAMETER_INTEGER: "integer_value",
        ParameterType.PARAMETER_DOUBLE: "double_value",
        ParameterType.PARAMETER_STRING: "string_value",
    }
    field = fields.get(param.value.type)
    if field is None:
        return [("type", param.value.type)]
    return [(field, getattr(param.value, field))]


def import_type(type_name: str) -> type:
    package, kind, name = type_name.split("/")
    return getattr(importlib.import_module(f"{package}.{kind}"), name)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mode", choices=("lifecycle", "fuzz"))
    parser.add_argument("nodes", nargs="+", help="fully qualified node names")
    parser.add_argument("--expect-service", action="append", default=[])
    parser.add_argument("--expect-action", action="append", default=[])
    options = parser.parse_args(argv)
    rclpy.init(args=[])
    client = None
    reported = False
    try:
        client = OutsideClient()
        if options.mode == "lifecycle":
            for node in options.nodes:
                client.run_lifecycle(node)
        else:
            client.run_fuzz(options.nodes, options.expect_service, options.expect_action)
        print(client.report.dump(), flush=True)
        reported = True
    finally:
        _tear_down(client, reported)
    return 0


TEARDOWN_LIMIT = 30.0  # s for this client's own executor, node and context to go


def _tear_down(client: OutsideClient | None, reported: bool) -> None:
    """End this client's ROS side, within TEARDOWN_LIMIT.

    The verdict is printed before: a teardown that hangs is this tool's, not the nodes'
    (rehearsal ci75: the report was complete, yet the process was still there 150 s in,
    at load 15). It says on stderr where it hung, for the test to record, and exits (with
    an error when there was no report: the exception under way is lost then).
    """
    stage = ["the executor's shutdown"]

    def run() -> None:
        if client is not None:
            client.spinner.shutdown()
            stage[0] = "destroying the node"
            client.destroy_node()
        stage[0] = "rclpy's shutdown"
        rclpy.try_shutdown()
        stage[0] = ""

    worker = threading.Thread(target=run, name="teardown", daemon=True)
    worker.start()
    worker.join(TEARDOWN_LIMIT)
    if worker.is_alive():
        print(f"teardown hung at {stage[0]} for {TEARDOWN_LIMIT:g} s", file=sys.stderr, flush=True)
        os._exit(0 if reported else 1)


if __name__ == "__main__":
    sys.exit(main())
