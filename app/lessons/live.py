"""What lessons do to and read from the live system: step actions and checks.

``LessonRuntime`` is used by the lesson panel's buttons and by the test that
walks every lesson, so both exercise the same code. Checks never block: a
check that needs a service answer issues ``call_async`` and reports
*waiting* until the answer is in.
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass
from typing import Any

from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetState
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import GetParameters, SetParameters
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy

from app import catalog
from app.graph import GraphSnapshot
from app.lessons.schema import Spec
from app.ros2cli.common import Ros2Error
from app.ros2cli.convert import fill, import_type
from app.ros2cli.topic import TopicMonitor
from app.supervisor import Supervisor

PASS, FAIL, WAITING = "pass", "fail", "waiting"
RECALL_PERIOD_SEC = 1.0
ACTION_SERVER_WAIT_SEC = 3.0
# Transitions are sent by label: the node picks the one valid from its current
# state ("shutdown" exists from unconfigured, inactive and active).
TRANSITIONS = ("configure", "cleanup", "activate", "deactivate", "shutdown")
# Best effort hears reliable and best-effort publishers alike (camera images
# are usually best effort); a reliable tap would hear only the former.
TAP_QOS = QoSProfile(depth=50, reliability=ReliabilityPolicy.BEST_EFFORT)
TAP_KEEP = 50  # messages a check can look back on


@dataclass(frozen=True)
class CheckResult:
    state: str  # pass | fail | waiting
    reason: str = ""


def _parameter_value(value: ParameterValue) -> Any:
    return {
        ParameterType.PARAMETER_BOOL: value.bool_value,
        ParameterType.PARAMETER_INTEGER: value.integer_value,
        ParameterType.PARAMETER_DOUBLE: value.double_value,
        ParameterType.PARAMETER_STRING: value.string_value,
    }.get(value.type)


def _to_parameter_value(value: Any) -> ParameterValue:
    if isinstance(value, bool):
        return ParameterValue(type=ParameterType.PARAMETER_BOOL, bool_value=value)
    if isinstance(value, int):
        return ParameterValue(type=ParameterType.PARAMETER_INTEGER, integer_value=value)
    if isinstance(value, float):
        return ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=value)
    return ParameterValue(type=ParameterType.PARAMETER_STRING, string_value=str(value))


class _Call:
    """The latest answer of a service that a check polls about once a second."""

    def __init__(self) -> None:
        self.future: Any = None
        self.result: Any = None
        self.sent_at = 0.0


class LessonRuntime:
    """Performs step actions and evaluates checks on the live graph. Thread-safe."""

    def __init__(self, node: Node, supervisor: Supervisor) -> None:
        self.node = node
        self.supervisor = supervisor
        self.graph = GraphSnapshot()
        self._lock = threading.Lock()
        self._taps: dict[tuple[str, str], TopicMonitor] = {}
        self._clients: dict[tuple[str, str], Any] = {}
        self._calls: dict[str, _Call] = {}
        self._action_clients: dict[tuple[str, str], ActionClient] = {}
        self.action_results: dict[str, str] = {}
        self.action_feedback: dict[str, list[Any]] = {}
        self.quiz_answers: dict[str, str] = {}
        self.last_action_message = ""

    # -- shared helpers ----------------------------------------------------

    def tap(self, topic: str, type_name: str) -> TopicMonitor:
        with self._lock:
            key = (topic, type_name)
            if key not in self._taps:
                self._taps[key] = TopicMonitor(
                    self.node, topic, import_type(type_name), keep=TAP_KEEP, qos=TAP_QOS
                )
            return self._taps[key]

    def _client(self, service: str, srv_type: type) -> Any:
        with self._lock:
            key = (service, srv_type.__name__)
            if key not in self._clients:
                self._clients[key] = self.node.create_client(srv_type, service)
            return self._clients[key]

    def _poll_service(self, key: str, service: str, srv_type: type, request: Any) -> Any:
        """Latest response (or None); re-asks at most once per RECALL_PERIOD_SEC."""
        client = self._client(service, srv_type)
        with self._lock:
            call = self._calls.setdefault(key, _Call())
            if call.future is not None and call.future.done():
                call.result = call.future.result()
                call.future = None
            due = time.monotonic() - call.sent_at > RECALL_PERIOD_SEC
            if call.future is None and due and client.service_is_ready():
                call.future = client.call_async(request)
                call.sent_at = time.monotonic()
            return call.result

    # -- actions -----------------------------------------------------------

    def perform(self, action: Spec) -> str:
        """Do one step action; returns a one-line message for the page."""
        kind = action.kind
        with self._lock:
            self._calls.clear()  # answers from before this action may be stale now
        if kind == "start":
            status = self.supervisor.start(action["node"])
            message = f"Started {action['node']} (pid {status.pid})."
        elif kind == "stop":
            self.supervisor.stop(action["node"])
            message = f"Stopping {action['node']}."
        elif kind in ("start_group", "stop_group"):
            group = catalog.lookup_group(action["group"])
            for member in group.members:
                if kind == "start_group":
                    self.supervisor.start(member)
                else:
                    self.supervisor.stop(member)
            verb = "Started" if kind == "start_group" else "Stopping"
            message = f"{verb} {', '.join(group.members)}."
        elif kind == "lifecycle":
            transition = action["transition"]
            if transition not in TRANSITIONS:
                raise ValueError(f"unknown lifecycle transition {transition!r}")
            client = self._client(f"{action['node']}/change_state", ChangeState)
            request = ChangeState.Request(transition=Transition(label=transition))
            client.call_async(request)
            message = f"Asked {action['node']} to {transition}."
        elif kind == "set_param":
            client = self._client(f"{action['node']}/set_parameters", SetParameters)
            param = Parameter(name=action["name"], value=_to_parameter_value(action["value"]))
            client.call_async(SetParameters.Request(parameters=[param]))
            message = f"Set {action['name']} = {action['value']!r} on {action['node']}."
        elif kind == "call_service":
            srv_type = import_type(action["type"])
            request = fill(srv_type.Request, action["request"])
            self._client(action["service"], srv_type).call_async(request)
            message = f"Called {action['service']}."
        elif kind == "send_goal":
            message = self._send_goal(action)
        elif kind == "open_panel":
            message = f"Open the {action['panel']} tab."
        else:  # the schema makes this unreachable
            raise ValueError(f"unknown action kind {kind!r}")
        self.last_action_message = message
        return message

    def _send_goal(self, action: Spec) -> str:
        name, type_name = action["action"], action["type"]
        action_type = import_type(type_name)
        with self._lock:
            client = self._action_clients.get((name, type_name))
            if client is None:
                client = ActionClient(self.node, action_type, name)
                self._action_clients[(name, type_name)] = client
        # A new client may not have discovered the server yet: wait briefly.
        if not client.wait_for_server(timeout_sec=ACTION_SERVER_WAIT_SEC):
            raise RuntimeError(f"no action server on {name}: start it first")
        cancel_after = action.get("cancel_after_feedback")
        feedback: list[Any] = []
        self.action_feedback[name] = feedback
        self.action_results[name] = "running"
        handle_box: list[Any] = []

        def on_feedback(msg: Any) -> None:
            feedback.append(msg.feedback)
            if cancel_after and len(feedback) == cancel_after and handle_box:
                handle_box[0].cancel_goal_async()

        def on_result(future: Any) -> None:
            status = future.result().status
            self.action_results[name] = {4: "succeeded", 5: "canceled", 6: "aborted"}.get(
                status, f"status {status}"
            )

        def on_goal(future: Any) -> None:
            handle = future.result()
            if not handle.accepted:
                self.action_results[name] = "rejected"
                return
            handle_box.append(handle)
            handle.get_result_async().add_done_callback(on_result)

        goal = fill(action_type.Goal, action["goal"])
        client.send_goal_async(goal, feedback_callback=on_feedback).add_done_callback(on_goal)
        return f"Sent a goal to {name}."

    # -- checks ------------------------------------------------------------

    def evaluate(self, check: Spec) -> CheckResult:
        try:
            return getattr(self, f"_check_{check.kind}")(check)
        except (Ros2Error, ValueError, RuntimeError, catalog.UnknownNodeError) as exc:
            return CheckResult(FAIL, str(exc))

    def _check_node_running(self, c: Spec) -> CheckResult:
        if self.graph.has_node(c["node"]):
            return CheckResult(PASS, f"{c['node']} is on the graph")
        return CheckResult(FAIL, f"{c['node']} is not on the graph")

    def _check_node_absent(self, c: Spec) -> CheckResult:
        if self.graph.has_node(c["node"]):
            return CheckResult(FAIL, f"{c['node']} is still on the graph")
        return CheckResult(PASS, f"{c['node']} is gone")

    def _publishers(self, topic: str) -> int:
        info = self.graph.topic(topic)
        return info.publishers if info else 0

    def _check_topic_messages(self, c: Spec) -> CheckResult:
        tap = self.tap(c["topic"], c["type"])
        if c.get("field"):
            # Newest first, and no further than needed: images are big to decode.
            count = 0
            for _, msg in tap.newest():
                count += c.get("contains", "") in str(getattr(msg, c["field"]))
                if count >= c["at_least"]:
                    break
        else:
            count = tap.count
        if count >= c["at_least"]:
            return CheckResult(PASS, f"{count} matching messages on {c['topic']}")
        if not self._publishers(c["topic"]):
            return CheckResult(FAIL, f"no publisher on {c['topic']}")
        return CheckResult(WAITING, f"{count} of {c['at_least']} messages on {c['topic']}")

    def _check_topic_rate(self, c: Spec) -> CheckResult:
        tap = self.tap(c["topic"], c["type"])
        rate = tap.rate_hz()
        if rate is None:
            if not self._publishers(c["topic"]):
                return CheckResult(FAIL, f"no publisher on {c['topic']}")
            return CheckResult(WAITING, f"measuring the rate of {c['topic']}")
        if c["min_hz"] <= rate <= c["max_hz"]:
            return CheckResult(PASS, f"{c['topic']} at {rate:.1f} Hz")
        return CheckResult(
            FAIL, f"{c['topic']} at {rate:.1f} Hz, expected {c['min_hz']}-{c['max_hz']} Hz"
        )

    def _check_topic_subscribers(self, c: Spec) -> CheckResult:
        # Count the learner's subscribers, not the dashboard's own taps.
        infos = self.node.get_subscriptions_info_by_topic(c["topic"])
        count = sum(1 for info in infos if info.node_name != self.node.get_name())
        if count >= c["at_least"]:
            return CheckResult(PASS, f"{count} subscribers on {c['topic']}")
        return CheckResult(FAIL, f"{count} of {c['at_least']} subscribers on {c['topic']}")

    def _check_log_contains(self, c: Spec) -> CheckResult:
        lines = [line for line in self.supervisor.output(c["node"]) if c["text"] in line]
        needed = c.get("at_least", 1)
        if len(lines) >= needed:
            return CheckResult(PASS, f"{len(lines)} log lines contain {c['text']!r}")
        if not self.supervisor.status(c["node"]).active:
            return CheckResult(FAIL, f"{c['node']} is not running")
        return CheckResult(WAITING, f"{len(lines)} of {needed} log lines so far")

    def _check_lifecycle_state(self, c: Spec) -> CheckResult:
        if not self.graph.has_node(c["node"]):
            return CheckResult(FAIL, f"{c['node']} is not on the graph")
        response = self._poll_service(c.key, f"{c['node']}/get_state", GetState, GetState.Request())
        if response is None:
            return CheckResult(WAITING, f"asking {c['node']} for its state")
        label = response.current_state.label
        if label == c["state"]:
            return CheckResult(PASS, f"{c['node']} is {label}")
        return CheckResult(FAIL, f"{c['node']} is {label}, not {c['state']}")

    def _check_parameter_equals(self, c: Spec) -> CheckResult:
        if not self.graph.has_node(c["node"]):
            return CheckResult(FAIL, f"{c['node']} is not on the graph")
        request = GetParameters.Request(names=[c["name"]])
        response = self._poll_service(c.key, f"{c['node']}/get_parameters", GetParameters, request)
        if response is None:
            return CheckResult(WAITING, f"asking {c['node']} for {c['name']}")
        if not response.values:
            return CheckResult(FAIL, f"{c['node']} has no parameter {c['name']}")
        value = _parameter_value(response.values[0])
        expected = c["value"]
        same = (
            math.isclose(value, expected, rel_tol=1e-9)
            if isinstance(value, float) and isinstance(expected, (int, float))
            else value == expected
        )
        if same:
            return CheckResult(PASS, f"{c['name']} = {value!r}")
        return CheckResult(FAIL, f"{c['name']} = {value!r}, expected {expected!r}")

    def _check_service_returns(self, c: Spec) -> CheckResult:
        srv_type = import_type(c["type"])
        if not self._client(c["service"], srv_type).service_is_ready():
            return CheckResult(FAIL, f"no server for {c['service']}")
        request = fill(srv_type.Request, c["request"])
        response = self._poll_service(c.key, c["service"], srv_type, request)
        if response is None:
            return CheckResult(WAITING, f"calling {c['service']}")
        value = getattr(response, c["field"])
        if value == c["equals"]:
            return CheckResult(PASS, f"{c['service']} answered {c['field']} = {value!r}")
        return CheckResult(FAIL, f"{c['field']} = {value!r}, expected {c['equals']!r}")

    def _check_action_result(self, c: Spec) -> CheckResult:
        status = self.action_results.get(c["action"])
        if status is None:
            return CheckResult(FAIL, f"no goal sent to {c['action']} yet")
        if status == "running":
            done = len(self.action_feedback.get(c["action"], []))
            return CheckResult(WAITING, f"goal running, {done} feedback messages so far")
        if status == c["status"]:
            return CheckResult(PASS, f"the goal {status}")
        return CheckResult(FAIL, f"the goal {status}, expected {c['status']}")

    def _check_pointcloud_points(self, c: Spec) -> CheckResult:
        tap = self.tap(c["topic"], "sensor_msgs/msg/PointCloud2")
        recent = tap.recent(1)
        if not recent:
            if not self._publishers(c["topic"]):
                return CheckResult(FAIL, f"no publisher on {c['topic']}")
            return CheckResult(WAITING, f"waiting for a cloud on {c['topic']}")
        cloud = recent[-1][1]
        points = cloud.width * cloud.height
        if points >= c["at_least"]:
            return CheckResult(PASS, f"the cloud has {points} points")
        return CheckResult(WAITING, f"the cloud has {points} of {c['at_least']} points")

    def _check_arm_reached(self, c: Spec) -> CheckResult:
        target_tap = self.tap("/pos_in_robot_base_frame", "geometry_msgs/msg/PointStamped")
        pose_tap = self.tap("/end_effector_pose", "geometry_msgs/msg/PoseStamped")
        target, pose = target_tap.recent(1), pose_tap.recent(1)
        if not target or not pose:
            if not self._publishers("/end_effector_pose"):
                return CheckResult(FAIL, "no arm is publishing /end_effector_pose")
            return CheckResult(WAITING, "waiting for a target and the arm's pose")
        t, p = target[-1][1].point, pose[-1][1].pose.position
        error = math.dist((t.x, t.y, t.z), (p.x, p.y, p.z))
        if error <= c["tolerance"]:
            return CheckResult(PASS, f"the gripper is {error * 1000:.0f} mm from the target")
        return CheckResult(WAITING, f"the gripper is {error * 1000:.0f} mm from the target")

    def _check_interface_exists(self, c: Spec) -> CheckResult:
        import_type(c["type"])  # an unknown type raises -> fail with the reason
        return CheckResult(PASS, f"{c['type']} is installed")

    def _check_quiz(self, c: Spec) -> CheckResult:
        answer = self.quiz_answers.get(c.key)
        if answer is None:
            return CheckResult(WAITING, "choose an answer")
        if answer == c["answer"]:
            return CheckResult(PASS, "correct")
        return CheckResult(FAIL, f"{answer!r} is not right; try again")
