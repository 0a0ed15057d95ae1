"""Generated "cheat" solutions: they replay the statement's example, not the task.

A learner can pass a grader that feeds the statement's own example by
printing its answers. Each exercise's ``example`` (what the statement shows)
becomes a node that answers every input with the example's output; the
hidden, random inputs of the probes must make it fail. One generator per
probe kind, keyed by the exercise's first input-taking probe.
"""

from __future__ import annotations

import textwrap

from app.exercises.model import Exercise

_MAIN = """
def main():
    rclpy.init()
    node = Cheat()
    try:
        rclpy.spin(node, executor=MultiThreadedExecutor())
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


main()
"""

_HEAD = """
import time
import rclpy
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
"""


def _node_name(exercise: Exercise) -> str:
    return exercise.node.rsplit("/", 1)[-1]


def _topic_feed(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "topic_feed")
    in_pkg, _, in_name = probe["type"].split("/")
    out_pkg, _, out_name = probe["output_type"].split("/")
    return f"""
from {in_pkg}.msg import {in_name}
from {out_pkg}.msg import {out_name}
OUTPUTS = {exercise.example["outputs"]!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.sent = 0
        self.publisher = self.create_publisher({out_name}, {probe["output"]!r}, 10)
        self.create_subscription({in_name}, {probe["publish"]!r}, self.on_input, 10)

    def on_input(self, _msg):
        value = OUTPUTS[self.sent % len(OUTPUTS)]
        self.sent += 1
        self.publisher.publish({out_name}({probe["field"]}=value))
"""


def _service_random(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "service_random")
    pkg, _, name = probe["type"].split("/")
    return f"""
from {pkg}.srv import {name}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.create_service({name}, {probe["service"]!r}, self.on_request)

    def on_request(self, _request, response):
        response.{probe["field"]} = {exercise.example["response"]!r}
        return response
"""


def _action_goal(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "action_goal")
    pkg, _, name = probe["type"].split("/")
    return f"""
from rclpy.action import ActionServer, CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from {pkg}.action import {name}
SEQUENCE = {exercise.example["sequence"]!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.server = ActionServer(
            self, {name}, {probe["action"]!r}, execute_callback=self.execute,
            cancel_callback=lambda _goal: CancelResponse.ACCEPT,
            callback_group=ReentrantCallbackGroup(),
        )

    def execute(self, goal_handle):
        # Feedback and cancel handled right; the answer is the statement's example.
        done = []
        for number in SEQUENCE + SEQUENCE:
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                return {name}.Result(sequence=done)
            done.append(number)
            goal_handle.publish_feedback({name}.Feedback(partial_sequence=done))
            time.sleep(0.2)
        goal_handle.succeed()
        return {name}.Result(sequence=SEQUENCE)
"""


def _param_set(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "param_set")
    then = next(p["then"] for p in exercise.probes if p.kind == "param_set" and "then" in p.fields)
    pkg, _, name = then["type"].split("/")
    return f"""
from rcl_interfaces.msg import SetParametersResult
from {pkg}.msg import {name}
EXAMPLE_HZ = {exercise.example["rate_hz"]!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        rate = self.declare_parameter({probe["name"]!r}, 2.0).value
        self.publisher = self.create_publisher({name}, {then["topic"]!r}, 10)
        self.timer = self.create_timer(1.0 / rate, self.on_timer)
        self.add_on_set_parameters_callback(self.on_set)

    def on_set(self, params):
        for param in params:
            if param.value <= 0:
                return SetParametersResult(successful=False, reason="must be positive")
        # Any accepted value: the rate of the statement's example.
        self.destroy_timer(self.timer)
        self.timer = self.create_timer(1.0 / EXAMPLE_HZ, self.on_timer)
        return SetParametersResult(successful=True)

    def on_timer(self):
        self.publisher.publish({name}())
"""


def _lifecycle_sequence(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "lifecycle_sequence")
    pkg, _, name = probe["type"].split("/")
    states, state = [], "unconfigured"
    after = {"configure": "inactive", "activate": "active", "deactivate": "inactive"}
    for transition in exercise.example["transitions"]:
        state = after.get(transition, "unconfigured")
        states.append(state)
    active_after = [i + 1 for i, s in enumerate(states) if s == "active"]
    return f"""
from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn
from {pkg}.msg import {name}
ACTIVE_AFTER = {active_after!r}  # transitions done when the example's node is active


class Cheat(LifecycleNode):
    # Publishes on a plain publisher whenever the example's order says "active".
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.done = 0
        self.publisher = None
        self.create_timer(0.2, self.on_timer)

    def _step(self):
        self.done += 1
        return TransitionCallbackReturn.SUCCESS

    def on_configure(self, state):
        if self.publisher is None:
            self.publisher = self.create_publisher({name}, {probe["topic"]!r}, 10)
        return self._step()

    def on_activate(self, state):
        return self._step()

    def on_deactivate(self, state):
        return self._step()

    def on_cleanup(self, state):
        return self._step()

    def on_timer(self):
        if self.publisher is not None and self.done in ACTIVE_AFTER:
            self.publisher.publish({name}(data="beacon"))
"""


def _topic_sequence(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "topic_sequence")
    pkg, _, name = probe["type"].split("/")
    return f"""
from {pkg}.msg import {name}
VALUES = {exercise.example["values"]!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.sent = 0
        self.publisher = self.create_publisher({name}, {probe["topic"]!r}, 10)
        self.create_timer(0.2, self.on_timer)

    def on_timer(self):
        value = VALUES[self.sent % len(VALUES)]
        self.sent += 1
        self.publisher.publish({name}({probe["field"]}=value))
"""


def _point_transform(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "point_transform")
    return f"""
from geometry_msgs.msg import PointStamped
OUTPUT = {exercise.example["output"]!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.publisher = self.create_publisher(PointStamped, {probe["output"]!r}, 10)
        self.create_subscription(PointStamped, {probe["publish"]!r}, self.on_point, 10)

    def on_point(self, msg):
        out = PointStamped()
        out.header.stamp = msg.header.stamp
        out.header.frame_id = {probe.get("frame_id", "base_link")!r}
        out.point.x, out.point.y, out.point.z = OUTPUT
        self.publisher.publish(out)
"""


GENERATORS = {
    "topic_feed": _topic_feed,
    "service_random": _service_random,
    "action_goal": _action_goal,
    "param_set": _param_set,
    "lifecycle_sequence": _lifecycle_sequence,
    "topic_sequence": _topic_sequence,
    "point_transform": _point_transform,
}


def input_probe(exercise: Exercise) -> str | None:
    """The kind of the exercise's first probe that feeds or drives the node, if any."""
    return next((p.kind for p in exercise.probes if p.kind in GENERATORS), None)


def cheat_code(exercise: Exercise) -> str:
    """A node that answers with the statement's example whatever the input."""
    kind = input_probe(exercise)
    if kind is None:
        raise ValueError(f"{exercise.slug}: no probe that takes input")
    body = GENERATORS[kind](exercise)
    return textwrap.dedent(_HEAD) + textwrap.dedent(body) + textwrap.dedent(_MAIN)
