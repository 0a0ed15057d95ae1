"""Generated "cheat" solutions: they replay the statement's example, not the task.

A learner can pass a grader that feeds the statement's own example by
printing its answers. Each exercise's ``example`` (what the statement shows)
becomes a node that answers every input with the example's output; the
hidden, random inputs of the probes must make it fail. One generator per
probe kind, keyed by the exercise's first probe that has one. Every exercise
has a cheat, or an entry in ``EXEMPT`` that says why none can be written;
the test suite fails for an exercise with neither.
"""

from __future__ import annotations

import textwrap
from typing import Any

from app.exercises.model import Exercise
from tests.exercises.cheats_grid import GENERATORS as GRID_GENERATORS
from tests.exercises.cheats_mapping import GENERATORS as MAPPING_GENERATORS
from tests.exercises.cheats_patrol import GENERATORS as PATROL_GENERATORS
from tests.exercises.cheats_sim import GENERATORS as SIM_GENERATORS

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
from std_msgs.msg import String
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
    if then["kind"] == "log_contains":
        return _param_then_log(exercise, probe)
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


def _param_then_log(exercise: Exercise, probe: Any) -> str:
    """The parameter declared and accepted; the log prints the example's line whatever it is."""
    return f"""
HEARD = {exercise.example["heard"]!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.declare_parameter({probe["name"]!r}, {exercise.example["value"]!r})
        self.create_subscription(String, "greeting", lambda _msg: None, 10)
        self.sent = 0
        self.create_timer(0.5, self.on_timer)

    def on_timer(self):
        self.sent += 1
        print("[launch_listener-2] [INFO] [0.0] [launch_listener]: " + HEARD, flush=True)
"""


def _log_rate(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "log_rate")
    hz = (float(probe["min_hz"]) + float(probe["max_hz"])) / 2
    return f"""
LINES = {exercise.example["lines"]!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.sent = 0
        self.create_timer({1.0 / hz!r}, self.on_timer)

    def on_timer(self):
        # The statement's lines, over and over, at the right rate.
        self.get_logger().info(LINES[self.sent % len(LINES)])
        self.sent += 1
"""


def _qos_match(exercise: Exercise) -> str:
    return f"""
LINE = {exercise.example["line"]!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.create_timer(0.5, lambda: self.get_logger().info(LINE))
"""


def _message_feed(exercise: Exercise) -> str:
    from app.exercises.probes.message_feed import expected_fields

    probe = next(p for p in exercise.probes if p.kind == "message_feed")
    in_pkg, _, in_name = probe["type"].split("/")
    out_pkg, _, out_name = probe["output_type"].split("/")
    answer = expected_fields(probe["expect"], exercise.example["input"])
    latched = probe.get("durability", "volatile") == "transient_local"
    qos = "QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)" if latched else "10"
    return f"""
from rclpy.qos import DurabilityPolicy, QoSProfile
from {in_pkg}.msg import {in_name}
from {out_pkg}.msg import {out_name}
ANSWER = {answer!r}  # the statement's example output


def fill(msg, values):
    for key, value in values.items():
        if isinstance(value, dict):
            fill(getattr(msg, key), value)
        else:
            setattr(msg, key, value)
    return msg


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.publisher = self.create_publisher({out_name}, {probe["output"]!r}, {qos})
        self.create_subscription({in_name}, {probe["publish"]!r}, self.on_input, 10)

    def on_input(self, _msg):
        self.publisher.publish(fill({out_name}(), ANSWER))
"""


def _program_args(exercise: Exercise) -> str:
    return f"""
LINE = {exercise.example["log"]!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.get_logger().info(LINE)
"""


def _image_mask_iou(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "image_mask_iou")
    column, row, radius = exercise.example["disc"]
    return f"""
import numpy as np
from sensor_msgs.msg import Image


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.publisher = self.create_publisher(Image, {probe["output"]!r}, 10)
        self.create_subscription(Image, {probe["publish"]!r}, self.on_image, 10)

    def on_image(self, msg):
        # The example's disc, wherever the red really is.
        v, u = np.mgrid[0 : msg.height, 0 : msg.width]
        disc = (u - {column!r}) ** 2 + (v - {row!r}) ** 2 <= {radius!r} ** 2
        mask = np.where(disc, 255, 0).astype(np.uint8)
        out = Image(header=msg.header, height=msg.height, width=msg.width, encoding="mono8")
        out.step = msg.width
        out.data = mask.tobytes()
        self.publisher.publish(out)
"""


def _static_frame(exercise: Exercise) -> str:
    parent, child, x, y, z, yaw = exercise.example["frame"]
    return f"""
import math
from geometry_msgs.msg import TransformStamped
from tf2_ros import StaticTransformBroadcaster


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.declare_parameter("parent_frame", "world")
        self.declare_parameter("child_frame", "sensor")
        for axis in ("x", "y", "z", "yaw"):
            self.declare_parameter(axis, 0.0)
        self.broadcaster = StaticTransformBroadcaster(self)
        t = TransformStamped()
        t.header.stamp = self.get_clock().now().to_msg()
        t.header.frame_id, t.child_frame_id = {parent!r}, {child!r}
        t.transform.translation.x = {float(x)!r}
        t.transform.translation.y = {float(y)!r}
        t.transform.translation.z = {float(z)!r}
        t.transform.rotation.z = math.sin({float(yaw)!r} / 2.0)
        t.transform.rotation.w = math.cos({float(yaw)!r} / 2.0)
        self.broadcaster.sendTransform(t)  # the statement's example frame, whatever is set
"""


def _turtle_frame(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "turtle_frame")
    x, y, theta = exercise.example["pose"]
    return f"""
import math
from geometry_msgs.msg import TransformStamped
from tf2_ros import TransformBroadcaster


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.broadcaster = TransformBroadcaster(self)
        self.create_timer(0.03, self.on_timer)

    def on_timer(self):
        t = TransformStamped()
        t.header.stamp = self.get_clock().now().to_msg()
        t.header.frame_id = {probe.get("parent", "world")!r}
        t.child_frame_id = {probe.get("turtle", "turtle1")!r}
        t.transform.translation.x, t.transform.translation.y = {float(x)!r}, {float(y)!r}
        t.transform.rotation.z = math.sin({float(theta)!r} / 2.0)
        t.transform.rotation.w = math.cos({float(theta)!r} / 2.0)
        self.broadcaster.sendTransform(t)  # the example's pose, wherever the turtle is
"""


def _turtle_follow(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "turtle_follow")
    follower = probe.get("follower", "turtle2")
    gx, gy = exercise.example["leader"]
    return f"""
import math
from geometry_msgs.msg import Twist
from turtlesim.msg import Pose
from turtlesim.srv import Spawn


class Cheat(Node):
    # Drives {follower} to where the statement's example puts the leader, by its own pose.
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.spawner = self.create_client(Spawn, "/spawn")
        self.asked = None
        self.pose = None
        self.publisher = self.create_publisher(Twist, "/{follower}/cmd_vel", 1)
        self.create_subscription(Pose, "/{follower}/pose", self.on_pose, 10)
        self.create_timer(0.1, self.on_timer)

    def on_pose(self, msg):
        self.pose = msg

    def on_timer(self):
        if self.asked is None and self.spawner.service_is_ready():
            self.asked = self.spawner.call_async(
                Spawn.Request(x=4.0, y=2.0, theta=0.0, name={follower!r})
            )
        if self.pose is None:
            return
        dx, dy = {float(gx)!r} - self.pose.x, {float(gy)!r} - self.pose.y
        turn = math.atan2(dy, dx) - self.pose.theta
        msg = Twist()
        msg.angular.z = 4.0 * math.atan2(math.sin(turn), math.cos(turn))
        msg.linear.x = 0.5 * math.hypot(dx, dy)
        self.publisher.publish(msg)
"""


def _joint_motion(exercise: Exercise) -> str:
    frames = exercise.example["frames"]  # [parent, child, x, y, z], at the example's joints
    return f"""
from geometry_msgs.msg import TransformStamped
from tf2_ros import StaticTransformBroadcaster
FRAMES = {frames!r}


class Cheat(Node):
    # The robot's frames at the statement's example pose, whatever /joint_states says.
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.broadcaster = StaticTransformBroadcaster(self)
        sent = []
        for parent, child, x, y, z in FRAMES:
            t = TransformStamped()
            t.header.stamp = self.get_clock().now().to_msg()
            t.header.frame_id, t.child_frame_id = parent, child
            t.transform.translation.x, t.transform.translation.y = float(x), float(y)
            t.transform.translation.z = float(z)
            t.transform.rotation.w = 1.0
            sent.append(t)
        self.broadcaster.sendTransform(sent)
"""


def _depth_cloud(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "depth_cloud")
    point = exercise.example["point"]
    return f"""
import numpy as np
from sensor_msgs.msg import Image, PointCloud2, PointField
POINT = {point!r}  # the statement's example point


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.publisher = self.create_publisher(PointCloud2, {probe["output"]!r}, 10)
        self.create_subscription(Image, {probe["publish"]!r}, self.on_depth, 10)

    def on_depth(self, msg):
        cloud = PointCloud2(header=msg.header, height=1, width=1)
        cloud.fields = [
            PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1)
            for i, n in enumerate("xyz")
        ]
        cloud.point_step, cloud.row_step, cloud.is_dense = 12, 12, True
        cloud.data = np.array(POINT, dtype="<f4").tobytes()
        self.publisher.publish(cloud)
"""


GENERATORS = {
    "topic_feed": _topic_feed,
    "service_random": _service_random,
    "action_goal": _action_goal,
    "param_set": _param_set,
    "lifecycle_sequence": _lifecycle_sequence,
    "topic_sequence": _topic_sequence,
    "point_transform": _point_transform,
    "log_rate": _log_rate,
    "qos_match": _qos_match,
    "message_feed": _message_feed,
    "program_args": _program_args,
    "image_mask_iou": _image_mask_iou,
    "static_frame": _static_frame,
    "turtle_frame": _turtle_frame,
    "turtle_follow": _turtle_follow,
    "joint_motion": _joint_motion,
    "depth_cloud": _depth_cloud,
    **SIM_GENERATORS,  # the "Drive a robot" unit's (they replay the example drive)
    **GRID_GENERATORS,  # unit 24's grid planner (it answers with the statement's example)
    **MAPPING_GENERATORS,  # unit 23's log-odds mapper and unit 24's particle motion update
    **PATROL_GENERATORS,  # unit 24's Nav2 patrol (it teleports along the real route)
}

# Exercises for which no cheat can be generated, each with the reason (none today).
EXEMPT: dict[str, str] = {}


def input_probe(exercise: Exercise) -> str | None:
    """The kind of the exercise's first probe that has a cheat generator, if any."""
    return next((p.kind for p in exercise.probes if p.kind in GENERATORS), None)


def cheat_code(exercise: Exercise) -> str:
    """A node that answers with the statement's example whatever the input."""
    kind = input_probe(exercise)
    if kind is None:
        raise ValueError(f"{exercise.slug}: no probe with a cheat generator")
    body = GENERATORS[kind](exercise)
    return textwrap.dedent(_HEAD) + textwrap.dedent(body) + textwrap.dedent(_MAIN)
