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
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from lifecycle_msgs.srv import ChangeState, GetState
from rcl_interfaces.srv import GetParameters, SetParameters
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from app import catalog
from app.bags.errors import BagError
from app.bags.folder import existing_path
from app.bags.info import read_info
from app.lessons.kinds import ACTION_KINDS, CHECK_KINDS
from app.lessons.schema import Spec
from app.ros import lifecycle, params
from app.ros.calls import GoalRun, ServicePoller, send_goal
from app.ros.context import CallContext, Limits
from app.ros.convert import fill, import_type
from app.ros.errors import Ros2Error
from app.ros.graph import GraphSnapshot
from app.ros.monitor import TopicMonitor
from app.supervisor import Supervisor

PASS, FAIL, WAITING = "pass", "fail", "waiting"
RECALL_PERIOD_SEC = 1.0
# A goal from a lesson button: wait a little for the server, then up to a minute.
GOAL_LIMITS = Limits(service_timeout=3.0, action_timeout=60.0)
# Best effort hears reliable and best-effort publishers alike (camera images
# are usually best effort); a reliable tap would hear only the former.
TAP_QOS = QoSProfile(depth=50, reliability=ReliabilityPolicy.BEST_EFFORT)
TAP_KEEP = 50  # messages a check can look back on
# /rosout keeps each node's recent log for late joiners (transient local, 10 s
# lifespan): a reliable, transient-local tap also reads what was logged just
# before the check first looked, e.g. right after the step's button.
ROSOUT_QOS = QoSProfile(
    depth=1000, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
ROSOUT_KEEP = 500


RATE_SECONDS = 4.0  # a rate is judged on about this long of the rate under test
RATE_MIN_SAMPLES, RATE_MAX_SAMPLES = 8, 60


def rate_samples_needed(check: Spec) -> int:
    """Messages a topic_rate check judges on: its ``samples``, else ~4 s at the mid rate."""
    if "samples" in check.fields:
        return int(check["samples"])
    mid = (float(check["min_hz"]) + float(check["max_hz"])) / 2
    return max(RATE_MIN_SAMPLES, min(RATE_MAX_SAMPLES, round(mid * RATE_SECONDS)))


@dataclass(frozen=True)
class CheckResult:
    state: str  # pass | fail | waiting
    reason: str = ""


class LessonRuntime:
    """Performs step actions and evaluates checks on the live graph.

    ``perform`` may block briefly (it starts processes): call it from a job,
    never a viser callback. ``evaluate`` never blocks: service answers come
    from a ``ServicePoller``, goals run on their own threads. The UI thread
    sets ``graph`` and calls both; the topic taps and the poller have their
    own locks, and ``quiz_answers`` is written only by the UI thread.
    """

    def __init__(self, node: Node, supervisor: Supervisor) -> None:
        self.node = node
        self.supervisor = supervisor
        self.graph = GraphSnapshot()
        self._lock = threading.Lock()
        self._taps: dict[tuple[str, str], TopicMonitor] = {}
        self._tap_born: dict[tuple[str, str], float] = {}  # when each tap began to listen
        self._services = ServicePoller(node, RECALL_PERIOD_SEC)
        self._goals: dict[str, GoalRun] = {}
        self._senders: dict[tuple[str, str], Any] = {}  # kept: a fresh one misses subscribers
        self.quiz_answers: dict[str, str] = {}
        # Runs a `ros2 ...` line in the Console tab (the dashboard wires it; UI thread).
        self.console: Callable[[str], None] | None = None

    def tap(self, topic: str, type_name: str, history: bool = False) -> TopicMonitor:
        """A kept subscription; ``history``: the reliable, transient-local /rosout kind."""
        with self._lock:
            key = (topic, type_name + (" (history)" if history else ""))
            if key not in self._taps:
                self._tap_born[key] = time.monotonic()
                self._taps[key] = TopicMonitor(
                    self.node,
                    topic,
                    import_type(type_name),
                    keep=ROSOUT_KEEP if history else TAP_KEEP,
                    qos=ROSOUT_QOS if history else TAP_QOS,
                )
            return self._taps[key]

    def close(self) -> None:
        with self._lock:
            taps, self._taps = list(self._taps.values()), {}
            goals = list(self._goals.values())
        for tap in taps:
            tap.close()
        for run in goals:
            run.cancel()
        self._services.close()

    # -- actions -----------------------------------------------------------

    def perform(self, action: Spec) -> str:
        """Do one step action; returns a one-line message for the page."""
        self._services.forget_answers()  # answers from before this action may be stale now
        return _ACTIONS[action.kind](self, action)

    def _start(self, action: Spec) -> str:
        status = self.supervisor.start(action["catalog_node"])
        return f"Started {action['catalog_node']} (pid {status.pid})."

    def _stop(self, action: Spec) -> str:
        self.supervisor.stop(action["catalog_node"])
        return f"Stopping {action['catalog_node']}."

    def _start_group(self, action: Spec) -> str:
        group = catalog.lookup_group(action["group"])
        for member in group.members:
            self.supervisor.start(member)
        return f"Started {', '.join(group.members)}."

    def _stop_group(self, action: Spec) -> str:
        group = catalog.lookup_group(action["group"])
        for member in group.members:
            self.supervisor.stop(member)
        return f"Stopping {', '.join(group.members)}."

    def _lifecycle(self, action: Spec) -> str:
        request = lifecycle.change_request(action["transition"])
        self._services.send(f"{action['node']}/change_state", ChangeState, request)
        return f"Asked {action['node']} to {action['transition']}."

    def _set_param(self, action: Spec) -> str:
        request = params.set_request(action["name"], action["value"])
        self._services.send(f"{action['node']}/set_parameters", SetParameters, request)
        return f"Set {action['name']} = {action['value']!r} on {action['node']}."

    def _publish(self, action: Spec) -> str:
        msg_type = import_type(action["type"])
        message = fill(msg_type, action["message"])
        times, period = int(action.get("times", 1)), 1.0 / float(action.get("rate_hz", 1.0))
        with self._lock:
            key = (action["topic"], action["type"])
            if key not in self._senders:
                self._senders[key] = self.node.create_publisher(msg_type, action["topic"], 10)
            publisher = self._senders[key]

        def send() -> None:  # off the UI thread: the burst takes times / rate_hz seconds
            for index in range(times):
                if index:
                    time.sleep(period)
                publisher.publish(message)

        threading.Thread(target=send, name=f"lesson-publish-{key[0]}", daemon=True).start()
        return f"Publishing {times} message(s) on {action['topic']}."

    def _call_service(self, action: Spec) -> str:
        srv_type = import_type(action["type"])
        request = fill(srv_type.Request, action["request"])
        self._services.send(action["service"], srv_type, request)
        return f"Called {action['service']}."

    def _send_goal(self, action: Spec) -> str:
        name, type_text = action["action"], action["type"]
        goal = fill(import_type(type_text, "action").Goal, action["goal"])
        run = GoalRun(name, type_text, goal)
        cancel_after = action.get("cancel_after_feedback")

        def on_feedback(_feedback: Any) -> None:
            if cancel_after and len(run.feedback) == cancel_after:
                run.cancel()

        with self._lock:
            self._goals[name] = run
        ctx = CallContext(self.node, limits=GOAL_LIMITS)

        def drive() -> None:
            try:
                send_goal(ctx, run, on_feedback)
            except Ros2Error:
                pass  # recorded in run.error; the check shows it

        threading.Thread(target=drive, name=f"lesson-goal-{name}", daemon=True).start()
        return f"Sent a goal to {name}."

    def _open_panel(self, action: Spec) -> str:
        return f"Open the {action['panel']} tab."

    def _console(self, action: Spec) -> str:
        command = action["command"]
        if self.console is None:
            return f"Type it in the Console tab: {command}"
        self.console(command)
        return f"Running in the Console tab: {command}"

    # -- checks ------------------------------------------------------------

    def evaluate(self, check: Spec) -> CheckResult:
        try:
            return _CHECKS[check.kind](self, check)
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
        return self.graph.publishers(topic)

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
        """Judged on enough messages (``samples``, else about 4 s of the rate under test),
        by the publisher's clock where the middleware gives it, over a window no
        longer than those messages need at the slowest accepted rate (older ones,
        e.g. from before a rate change, do not count)."""
        tap = self.tap(c["topic"], c["type"])
        needed = rate_samples_needed(c)
        window = (needed + 1) / c["min_hz"] if c["min_hz"] > 0 else None
        stats = tap.published_rate(window)
        got = 0 if stats is None else (stats.published or stats.received)
        listened = time.monotonic() - self._tap_born.get((c["topic"], c["type"]), time.monotonic())
        if stats is None or (got < needed and (window is None or listened < window)):
            if not self._publishers(c["topic"]):
                return CheckResult(FAIL, f"no publisher on {c['topic']}")
            return CheckResult(
                WAITING, f"measuring the rate of {c['topic']}: {got} of {needed} messages"
            )
        how = "by the publisher's clock" if not stats.fallback else "by arrival times"
        text = f"{c['topic']} at {stats.rate:.2f} Hz over {got} messages ({how})"
        if c["min_hz"] <= stats.rate <= c["max_hz"] and got >= needed:
            return CheckResult(PASS, text)
        return CheckResult(FAIL, f"{text}, expected {c['min_hz']}-{c['max_hz']} Hz")

    def _check_topic_subscribers(self, c: Spec) -> CheckResult:
        # Count the learner's subscribers, not the dashboard's own taps.
        infos = self.node.get_subscriptions_info_by_topic(c["topic"])
        count = sum(1 for info in infos if info.node_name != self.node.get_name())
        if count >= c["at_least"]:
            return CheckResult(PASS, f"{count} subscribers on {c['topic']}")
        return CheckResult(FAIL, f"{count} of {c['at_least']} subscribers on {c['topic']}")

    def _check_log_contains(self, c: Spec) -> CheckResult:
        name = c["catalog_node"]
        lines = [line for line in self.supervisor.output(name) if c["text"] in line]
        needed = c.get("at_least", 1)
        if len(lines) >= needed:
            return CheckResult(PASS, f"{len(lines)} log lines contain {c['text']!r}")
        if not self.supervisor.status(name).active:
            return CheckResult(FAIL, f"{name} is not running")
        return CheckResult(
            WAITING, f"{len(lines)} of {needed} log lines contain {c['text']!r} so far"
        )

    def _check_bag_contains(self, c: Spec) -> CheckResult:
        """A finished, readable bag in the learner's bags folder holds enough of a topic."""
        try:
            info = read_info(existing_path(c["bag"]))
        except BagError as exc:  # absent, still recording (no metadata yet), or unreadable
            return CheckResult(FAIL, str(exc))
        count = next((t.count for t in info.topics if t.name == c["topic"]), 0)
        if count >= c["at_least"]:
            return CheckResult(PASS, f"{c['bag']} holds {count} messages of {c['topic']}")
        return CheckResult(FAIL, f"{c['bag']} holds {count} of {c['at_least']} on {c['topic']}")

    def _check_lifecycle_state(self, c: Spec) -> CheckResult:
        if not self.graph.has_node(c["node"]):
            return CheckResult(FAIL, f"{c['node']} is not on the graph")
        response = self._services.latest(
            c.key, f"{c['node']}/get_state", GetState, GetState.Request()
        )
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
        response = self._services.latest(
            c.key, f"{c['node']}/get_parameters", GetParameters, request
        )
        if response is None:
            return CheckResult(WAITING, f"asking {c['node']} for {c['name']}")
        if not response.values:
            return CheckResult(FAIL, f"{c['node']} has no parameter {c['name']}")
        value = params.python_value(response.values[0])
        expected = c["value"]
        if params.same_value(value, expected):
            return CheckResult(PASS, f"{c['name']} = {value!r}")
        return CheckResult(FAIL, f"{c['name']} = {value!r}, expected {expected!r}")

    def _check_service_returns(self, c: Spec) -> CheckResult:
        srv_type = import_type(c["type"])
        if not self._services.client(c["service"], srv_type).service_is_ready():
            return CheckResult(FAIL, f"no server for {c['service']}")
        request = fill(srv_type.Request, c["request"])
        response = self._services.latest(c.key, c["service"], srv_type, request)
        if response is None:
            return CheckResult(WAITING, f"calling {c['service']}")
        value = getattr(response, c["field"])
        if value == c["equals"]:
            return CheckResult(PASS, f"{c['service']} answered {c['field']} = {value!r}")
        return CheckResult(FAIL, f"{c['field']} = {value!r}, expected {c['equals']!r}")

    def _check_action_result(self, c: Spec) -> CheckResult:
        with self._lock:
            run = self._goals.get(c["action"])
        if run is None:
            return CheckResult(FAIL, f"no goal sent to {c['action']} yet")
        status = run.outcome
        if status == "running":
            done = len(run.feedback)
            return CheckResult(WAITING, f"goal running, {done} feedback messages so far")
        if run.error:
            return CheckResult(FAIL, run.error)
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

    def _check_moved_from(self, c: Spec) -> CheckResult:
        """The newest pose (any message with x and y) is far enough from a start point."""
        tap = self.tap(c["topic"], c["type"])
        newest = tap.message()
        if newest is None:
            if not self._publishers(c["topic"]):
                return CheckResult(FAIL, f"no publisher on {c['topic']}")
            return CheckResult(WAITING, f"waiting for a message on {c['topic']}")
        msg = newest[1]
        distance = math.dist((msg.x, msg.y), (c["x"], c["y"]))
        where = f"({c['x']:g}, {c['y']:g})"
        if distance >= c["at_least"]:
            return CheckResult(PASS, f"{c['topic']} is {distance:.2f} m from {where}")
        return CheckResult(
            WAITING, f"{c['topic']} is {distance:.2f} m from {where}; {c['at_least']:g} m needed"
        )

    def _check_moves_like(self, c: Spec) -> CheckResult:
        """``topic``'s newest pose moves with the velocities of ``like``'s, and is not still."""
        follower, leader = self.tap(c["topic"], c["type"]), self.tap(c["like"], c["type"])
        for tap in (follower, leader):
            if not self._publishers(tap.topic):
                return CheckResult(FAIL, f"no publisher on {tap.topic}")
        newest_follower, newest_leader = follower.message(), leader.message()
        if newest_follower is None or newest_leader is None:
            return CheckResult(WAITING, f"waiting for poses on {c['topic']} and {c['like']}")
        f, lead = newest_follower[1], newest_leader[1]
        speeds = f"{lead.linear_velocity:.2f} m/s, {lead.angular_velocity:.2f} rad/s"
        if abs(lead.linear_velocity) + abs(lead.angular_velocity) < 0.01:
            return CheckResult(WAITING, f"{c['like']} is standing still; make it move")
        if math.isclose(f.linear_velocity, lead.linear_velocity, abs_tol=0.05) and math.isclose(
            f.angular_velocity, lead.angular_velocity, abs_tol=0.05
        ):
            return CheckResult(PASS, f"{c['topic']} moves like {c['like']} ({speeds})")
        return CheckResult(
            WAITING,
            f"{c['topic']} at {f.linear_velocity:.2f} m/s, {f.angular_velocity:.2f} rad/s; "
            f"{c['like']} at {speeds}",
        )

    def _check_rosout_contains(self, c: Spec) -> CheckResult:
        """A node's log message reached /rosout (what rqt_console and the Logs tab read)."""
        if not self.graph.has_node(c["node"]):
            return CheckResult(FAIL, f"{c['node']} is not on the graph")
        logger = c["node"].strip("/").replace("/", ".")  # rcl names a node's logger so
        tap = self.tap("/rosout", "rcl_interfaces/msg/Log", history=True)
        needed = c.get("at_least", 1)
        count = 0
        for _, log in tap.newest():
            count += log.name == logger and c["text"] in log.msg
            if count >= needed:
                return CheckResult(PASS, f"{c['node']} logged {c['text']!r} on /rosout")
        return CheckResult(
            WAITING,
            f"{count} of {needed} messages from {c['node']} on /rosout contain {c['text']!r}",
        )

    def _check_quiz(self, c: Spec) -> CheckResult:
        answer = self.quiz_answers.get(c.key)
        if answer is None:
            return CheckResult(WAITING, "choose an answer")
        if answer == c["answer"]:
            return CheckResult(PASS, "correct")
        return CheckResult(FAIL, f"{answer!r} is not right; try again")


# The registry's kinds, each mapped to its implementation (checked at import).
_ACTIONS: dict[str, Callable[[LessonRuntime, Spec], str]] = {
    "start": LessonRuntime._start,
    "stop": LessonRuntime._stop,
    "start_group": LessonRuntime._start_group,
    "stop_group": LessonRuntime._stop_group,
    "lifecycle": LessonRuntime._lifecycle,
    "set_param": LessonRuntime._set_param,
    "call_service": LessonRuntime._call_service,
    "send_goal": LessonRuntime._send_goal,
    "open_panel": LessonRuntime._open_panel,
    "console": LessonRuntime._console,
    "publish": LessonRuntime._publish,
}
_CHECKS: dict[str, Callable[[LessonRuntime, Spec], CheckResult]] = {
    kind: getattr(LessonRuntime, f"_check_{kind}") for kind in CHECK_KINDS
}
if set(_ACTIONS) != set(ACTION_KINDS):
    raise RuntimeError(f"lesson actions without a handler: {set(ACTION_KINDS) ^ set(_ACTIONS)}")
