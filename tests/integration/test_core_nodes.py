"""The core tutorial nodes, each run as a process and checked over DDS from the probe node."""

from __future__ import annotations

import time

import pytest
from action_msgs.msg import GoalStatus
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetState
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64, String
from tutorial_interfaces.action import Fibonacci
from tutorial_interfaces.srv import AddTwoInts

from app.ros.action_client import ThreadSafeActionClient
from app.ros.monitor import TopicMonitor
from app.supervisor import NodeState
from tests.conftest import wait_until
from tests.integration.core_helpers import (
    DISCOVERY_TIMEOUT,
    call_service,
    node_names,
    output_has,
    set_parameters,
    wait_for_output,
)

pytestmark = pytest.mark.ros


def fib(order: int) -> list[int]:
    seq = [0, 1][: order + 1]
    while len(seq) < order + 1:
        seq.append(seq[-1] + seq[-2])
    return seq


def wait_state(supervisor, name: str, state: NodeState, timeout: float = DISCOVERY_TIMEOUT):
    return wait_until(
        lambda: (s := supervisor.status(name)).state is state and s,
        timeout=timeout,
        what=f"{name} to be {state.value}: {supervisor.output(name, last=10)}",
    )


# -- minimal nodes -------------------------------------------------------------


def test_minimal_nodes_say_hello_at_5_hz(supervisor, probe):
    supervisor.start("minimal_node")
    supervisor.start("minimal_node_procedural")
    wait_until(
        lambda: {"/minimal_node", "/minimal_node_procedural"} <= node_names(probe),
        timeout=DISCOVERY_TIMEOUT,
        what="both minimal nodes in the graph",
    )
    for name in ("minimal_node", "minimal_node_procedural"):
        wait_for_output(supervisor, name, "Hello ROS2")
    # 5 Hz: over 2 s each logs about 10 more lines (bounds loose for a loaded CPU).
    before = {n: len(supervisor.output(n)) for n in ("minimal_node", "minimal_node_procedural")}
    time.sleep(2.0)
    for name, count in before.items():
        new_lines = supervisor.output(name)[count:]
        assert all(line.endswith("Hello ROS2") for line in new_lines), new_lines
        assert 5 <= len(new_lines) <= 13, (name, len(new_lines))
    assert any("[minimal_node]" in line for line in supervisor.output("minimal_node"))


# -- service -------------------------------------------------------------------


def test_add_two_ints_client_waits_then_prints_the_sum(supervisor, probe):
    supervisor.start("add_two_ints_client")  # 2 + 3, started before any server
    wait_for_output(supervisor, "add_two_ints_client", "waiting for a server")
    assert supervisor.status("add_two_ints_client").active

    supervisor.start("add_two_ints_server")
    status = wait_state(supervisor, "add_two_ints_client", NodeState.EXITED)
    assert status.exit_code == 0
    assert output_has(supervisor, "add_two_ints_client", "Result of add_two_ints: 2 + 3 = 5")
    wait_for_output(supervisor, "add_two_ints_server", "a=2 b=3 -> sum=5")

    response = call_service(probe, AddTwoInts, "/add_two_ints", AddTwoInts.Request(a=40, b=-2))
    assert response.sum == 38
    assert "/add_two_ints_server" in node_names(probe)


# -- action --------------------------------------------------------------------


class ProbeGoal:
    """One Fibonacci goal sent from the probe, with its feedback and result."""

    def __init__(self, client: ThreadSafeActionClient, order: int) -> None:
        self.order = order
        self.feedback: list[list[int]] = []
        self._send = client.send_goal_async(
            Fibonacci.Goal(order=order),
            feedback_callback=lambda msg: self.feedback.append(list(msg.feedback.partial_sequence)),
        )
        self.handle = wait_until(
            lambda: self._send.done() and self._send.result(),
            timeout=30,  # a loaded machine answered after more than 15 s
            what=f"goal {order} response",
        )
        self._result = self.handle.get_result_async() if self.handle.accepted else None

    def result(self, timeout: float = 30.0):
        assert self._result is not None, "goal was rejected"
        wait_until(self._result.done, timeout=timeout, what=f"goal {self.order} result")
        response = self._result.result()
        return response.status, list(response.result.sequence)


def _wait_feedback_flows(client: ThreadSafeActionClient) -> None:
    """Feedback is a topic: until the server's side has discovered this client's feedback
    subscription (ready says only that the client sees the server), feedback goes nowhere,
    as for any ROS client (CI: a loaded machine's first goal succeeded, none of its
    feedback arrived). Short goals until one's feedback does."""
    deadline = time.monotonic() + DISCOVERY_TIMEOUT
    while True:
        goal = ProbeGoal(client, 1)
        assert goal.result()[0] == GoalStatus.STATUS_SUCCEEDED
        settle = time.monotonic() + 1.0  # feedback may trail the result (another channel)
        while not goal.feedback and time.monotonic() < settle:
            time.sleep(0.05)
        if goal.feedback:
            return
        assert time.monotonic() < deadline, "no feedback from any /fibonacci goal"


def test_fibonacci_feedback_result_rejection_cancel_and_preemption(supervisor, probe):
    supervisor.start("fibonacci_action_server", ["-p", "step_period:=0.1"])
    client = ThreadSafeActionClient(probe.node, Fibonacci, "/fibonacci")
    wait_until(client.server_is_ready, timeout=DISCOVERY_TIMEOUT, what="the /fibonacci server")
    _wait_feedback_flows(client)

    # Feedback grows one number per step; the result has order + 1 numbers. Feedback
    # is a topic and the result a service: rclpy's ActionClient forgets a goal's
    # feedback callback once its result is in, so the last step's feedback may be
    # dropped when the result overtakes it (CI: got up to [0, 1, 1, 2, 3, 5]).
    goal = ProbeGoal(client, 6)
    assert goal.handle.accepted
    assert goal.result() == (GoalStatus.STATUS_SUCCEEDED, [0, 1, 1, 2, 3, 5, 8])
    assert len(goal.feedback) >= 3, goal.feedback
    assert all(fb == fib(len(fb) - 1) for fb in goal.feedback)
    lengths = [len(fb) for fb in goal.feedback]
    assert lengths == sorted(set(lengths))  # one new number per feedback message
    assert ProbeGoal(client, 0).result() == (GoalStatus.STATUS_SUCCEEDED, [0])
    assert ProbeGoal(client, 46).handle.accepted  # upper bound of the range (preempted below)

    # Out of range: rejected, with the reason in the server's log.
    for order in (47, -1):
        assert not ProbeGoal(client, order).handle.accepted
        wait_for_output(supervisor, "fibonacci_action_server", f"order {order} is outside 0..46")

    # Cancel mid-goal: CANCELED with the numbers computed so far.
    goal = ProbeGoal(client, 40)
    wait_until(lambda: len(goal.feedback) >= 3, what="feedback before cancelling")
    cancel = goal.handle.cancel_goal_async()
    wait_until(cancel.done, what="the cancel response")
    assert len(cancel.result().goals_canceling) == 1
    status, sequence = goal.result()
    assert status == GoalStatus.STATUS_CANCELED
    assert 3 <= len(sequence) < 41 and sequence == fib(len(sequence) - 1)

    # Concurrent goals: the newest wins, the running one is aborted.
    older = ProbeGoal(client, 40)
    wait_until(lambda: len(older.feedback) >= 2, what="the older goal to run")
    newer = ProbeGoal(client, 3)
    assert newer.result() == (GoalStatus.STATUS_SUCCEEDED, [0, 1, 1, 2])
    status, sequence = older.result()
    assert status == GoalStatus.STATUS_ABORTED
    assert len(sequence) < 41
    wait_for_output(supervisor, "fibonacci_action_server", "aborting the goal still running")

    # The client program: feedback, result, exit code 0.
    supervisor.start("fibonacci_action_client")  # order 10
    status = wait_state(supervisor, "fibonacci_action_client", NodeState.EXITED, timeout=40)
    assert status.exit_code == 0
    out = supervisor.output("fibonacci_action_client")
    assert any("Feedback: [0, 1, 1, 2]" in line for line in out), out
    assert any(f"Result (SUCCEEDED): {fib(10)}" in line for line in out), out

    # Ctrl+C while a goal executes: the server still stops cleanly.
    running = ProbeGoal(client, 40)
    wait_until(lambda: len(running.feedback) >= 2, what="a goal running before the stop")
    stopped = supervisor.stop("fibonacci_action_server").result(timeout=20)
    assert stopped.exit_code == 0, supervisor.output("fibonacci_action_server", last=20)
    assert not output_has(supervisor, "fibonacci_action_server", "Traceback"), "\n".join(
        supervisor.output("fibonacci_action_server", last=30)
    )


# -- lifecycle -----------------------------------------------------------------

LIFECYCLE = "/lifecycle_talker"


def change_state(probe, transition_id: int) -> bool:
    request = ChangeState.Request(transition=Transition(id=transition_id))
    return call_service(probe, ChangeState, f"{LIFECYCLE}/change_state", request).success


def current_state(probe) -> str:
    return call_service(
        probe, GetState, f"{LIFECYCLE}/get_state", GetState.Request()
    ).current_state.label


def assert_silent(tap: TopicMonitor, seconds: float = 1.5) -> None:
    time.sleep(0.5)  # let anything already in flight land
    count = tap.count
    time.sleep(seconds)
    assert tap.count == count, "messages arrived while the node was not active"


def test_lifecycle_talker_every_transition_and_the_failing_one(supervisor, probe):
    tap = TopicMonitor(probe.node, "/lifecycle_chatter", String, qos=10)
    supervisor.start("lifecycle_talker", ["-p", "publish_period:=0.1"])
    assert current_state(probe) == "unconfigured"
    assert probe.node.count_publishers("/lifecycle_chatter") == 0

    # configure: the publisher exists, but an inactive node sends nothing.
    assert change_state(probe, Transition.TRANSITION_CONFIGURE)
    assert current_state(probe) == "inactive"
    wait_until(
        lambda: probe.node.count_publishers("/lifecycle_chatter") == 1,
        timeout=DISCOVERY_TIMEOUT,
        what="the lifecycle publisher in the graph",
    )
    assert_silent(tap)
    assert tap.count == 0

    # A transition made to fail on purpose: FAILURE, and the state is unchanged.
    assert set_parameters(probe, LIFECYCLE, fail_on="activate")[0].successful
    assert not change_state(probe, Transition.TRANSITION_ACTIVATE)
    assert current_state(probe) == "inactive"
    wait_for_output(supervisor, "lifecycle_talker", "on_activate: failing on purpose")
    rejected = set_parameters(probe, LIFECYCLE, fail_on="explode")[0]
    assert not rejected.successful and "fail_on must be empty or one of" in rejected.reason
    assert set_parameters(probe, LIFECYCLE, fail_on="")[0].successful

    # activate: messages flow.
    assert change_state(probe, Transition.TRANSITION_ACTIVATE)
    assert current_state(probe) == "active"
    wait_until(lambda: tap.count >= 3, timeout=DISCOVERY_TIMEOUT, what="lifecycle messages")
    assert tap.recent()[-1][1].data.startswith("Lifecycle Hello World: ")

    # deactivate: silent again, though the timer still runs.
    assert change_state(probe, Transition.TRANSITION_DEACTIVATE)
    assert current_state(probe) == "inactive"
    assert_silent(tap)

    # cleanup: the publisher is destroyed.
    assert change_state(probe, Transition.TRANSITION_CLEANUP)
    assert current_state(probe) == "unconfigured"
    wait_until(
        lambda: probe.node.count_publishers("/lifecycle_chatter") == 0,
        timeout=DISCOVERY_TIMEOUT,
        what="the publisher to disappear after cleanup",
    )

    # A failing configure, then shutdown from unconfigured to finalized.
    assert set_parameters(probe, LIFECYCLE, fail_on="configure")[0].successful
    assert not change_state(probe, Transition.TRANSITION_CONFIGURE)
    assert current_state(probe) == "unconfigured"
    assert change_state(probe, Transition.TRANSITION_UNCONFIGURED_SHUTDOWN)
    assert current_state(probe) == "finalized"

    out = "\n".join(supervisor.output("lifecycle_talker"))
    for text in (
        "on_configure: created the publisher",
        "on_activate: publisher enabled",
        "on_deactivate: publisher disabled",
        "on_cleanup: destroyed",
        "on_configure: failing on purpose",
        "on_shutdown from 'unconfigured'",
    ):
        assert text in out, text


# -- parameters ----------------------------------------------------------------


def test_parameters_node_accepts_and_rejects_changes(supervisor, probe):
    tap = TopicMonitor(probe.node, "/greeting", String, qos=10)
    supervisor.start("parameters_node")
    wait_until(lambda: tap.count >= 2, timeout=DISCOVERY_TIMEOUT, what="/greeting messages")
    assert tap.recent()[-1][1].data.startswith("Hello from parameters_node #")

    # Accepted: a new greeting and a faster rate, visible at once.
    results = set_parameters(probe, "/parameters_node", greeting="Bonjour", publish_rate_hz=10.0)
    assert all(r.successful for r in results), results
    wait_until(
        lambda: tap.recent()[-1][1].data.startswith("Bonjour from parameters_node #"),
        what="the new greeting",
    )
    time.sleep(2.5)
    rate = tap.rate_hz(window_sec=2.0)
    assert rate is not None and 5.0 <= rate <= 16.0, rate  # was 2 Hz
    assert set_parameters(probe, "/parameters_node", shout=True)[0].successful
    wait_until(
        lambda: tap.recent()[-1][1].data.startswith("BONJOUR FROM PARAMETERS_NODE #"),
        what="the shouted greeting",
    )

    # Rejected, each with a reason: by the descriptor's range and type, by our callback.
    out_of_range = set_parameters(probe, "/parameters_node", publish_rate_hz=100.0)[0]
    assert not out_of_range.successful and "out of range" in out_of_range.reason
    wrong_type = set_parameters(probe, "/parameters_node", publish_rate_hz="fast")[0]
    assert not wrong_type.successful and wrong_type.reason
    empty = set_parameters(probe, "/parameters_node", greeting="   ")[0]
    assert not empty.successful and empty.reason == "greeting must not be empty"
    too_long = set_parameters(probe, "/parameters_node", greeting="x" * 61)[0]
    assert not too_long.successful and "at most 60 characters" in too_long.reason
    time.sleep(0.5)
    assert tap.recent()[-1][1].data.startswith("BONJOUR")
    assert output_has(supervisor, "parameters_node", "Parameter publish_rate_hz is now 10.0")


# -- QoS -----------------------------------------------------------------------


def test_qos_mismatch_is_reported_and_compatible_pairs_talk(supervisor, probe):
    supervisor.start("qos_talker_best_effort")
    supervisor.start("qos_listener")  # reliable: cannot use a best-effort publisher
    supervisor.start("qos_listener_best_effort")

    wait_for_output(supervisor, "qos_listener", "INCOMPATIBLE QoS")
    assert output_has(supervisor, "qos_listener", "policy RELIABILITY")
    wait_for_output(supervisor, "qos_talker_best_effort", "INCOMPATIBLE QoS")
    wait_for_output(supervisor, "qos_listener_best_effort", 'I heard: "QoS message')
    time.sleep(1.0)
    assert not output_has(supervisor, "qos_listener", "I heard")

    # A best-effort subscriber on the probe hears the best-effort talker too.
    best_effort = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
    tap = TopicMonitor(probe.node, "/qos_chatter", String, qos=best_effort)
    wait_until(lambda: tap.count >= 2, timeout=DISCOVERY_TIMEOUT, what="best-effort messages")


def test_qos_transient_local_history_reaches_a_late_joiner(supervisor, probe):
    supervisor.start("qos_talker_transient_local")
    wait_for_output(supervisor, "qos_talker_transient_local", 'Publishing: "QoS message 3"')
    # Two late joiners at the same moment: only the transient-local one gets old messages.
    history = QoSProfile(
        depth=10,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    late = TopicMonitor(probe.node, "/qos_chatter", String, qos=history)
    fresh = TopicMonitor(probe.node, "/qos_chatter", String, qos=10)
    wait_until(
        lambda: late.count >= 1 and fresh.count >= 1,
        timeout=DISCOVERY_TIMEOUT,
        what="messages for both late joiners",
    )

    def first_number(tap: TopicMonitor) -> int:
        return int(tap.recent()[0][1].data.rsplit(" ", 1)[1])

    assert first_number(late) < first_number(fresh), (first_number(late), first_number(fresh))


# -- executors -----------------------------------------------------------------


def test_executor_demo_single_thread_starves_multi_thread_does_not(supervisor, probe):
    single = TopicMonitor(probe.node, "/executor_demo/fast_rate", Float64, qos=10)
    multi = TopicMonitor(probe.node, "/executor_demo_multi/fast_rate", Float64, qos=10)
    supervisor.start("executor_demo")
    supervisor.start("executor_demo_multi")
    # The first report covers a short window; use the later ones.
    wait_until(lambda: single.count >= 3 and multi.count >= 3, timeout=40, what="rate reports")
    single_rate = single.recent()[-1][1].data
    multi_rate = multi.recent()[-1][1].data
    assert multi_rate >= 6.0, multi_rate  # about 10 Hz: nothing blocks the fast timer
    assert single_rate <= 5.0, single_rate  # about 3 Hz: starved by the slow callback
    assert multi_rate >= 1.5 * single_rate
    wait_for_output(supervisor, "executor_demo", "[single] fast timer")
    wait_for_output(supervisor, "executor_demo_multi", "[multi] fast timer")
    for name in ("executor_demo", "executor_demo_multi"):  # even mid slow callback
        assert supervisor.stop(name).result(timeout=20).exit_code == 0, supervisor.output(name)


def test_a_goal_whose_acceptance_is_lost_is_followed_by_its_feedback(
    supervisor, probe, monkeypatch
):
    """Under load DDS may drop the goal's acceptance while the goal runs: follow the feedback."""
    from app.ros import calls
    from app.ros.context import CallContext, Limits
    from app.ros.errors import Ros2Error

    supervisor.start("fibonacci_action_server", ["-p", "step_period:=0.3"])
    real_wait = calls.wait_future
    lost = []

    def lose_the_acceptance(ctx, future, timeout, what):
        if not lost:  # the first wait is the acceptance: it never comes
            lost.append(what)
            ctx.sleep(1.5)  # long enough for feedback to arrive
            future.cancel()
            raise Ros2Error(f"no answer from {what} within {timeout:g} s")
        return real_wait(ctx, future, timeout, what)

    monkeypatch.setattr(calls, "wait_future", lose_the_acceptance)
    run = calls.GoalRun(
        "/fibonacci", "tutorial_interfaces/action/Fibonacci", Fibonacci.Goal(order=5)
    )
    ctx = CallContext(probe.node, limits=Limits(service_timeout=15.0, action_timeout=30.0))
    calls.send_goal(ctx, run)
    assert lost == ["action server '/fibonacci'"]
    assert run.status == "SUCCEEDED" and list(run.result.sequence) == [0, 1, 1, 2, 3, 5]
