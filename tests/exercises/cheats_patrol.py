"""Generated "cheat" for the Nav2 patrol (probe ``sim_patrol``): it teleports instead of driving.

The patrol is graded on the simulator's ground truth: each waypoint reached,
stopped at, in order, no touch, and ``Patrol finished`` printed after the
last. A script could read the route and put the robot on each waypoint with
the world's own controls (its start-pose parameters and ``/reset_world``, as
the grader itself puts the robot at the start), then say it is done. Every
one of those checks would pass; only the robot's jumps give it away, and the
probe must fail it for them.

The generator returns a node body (a ``class Cheat(Node)`` named as the
exercise's node), in the form ``tests/exercises/cheats.py`` wraps with its
imports and ``main`` (its GENERATORS include these).
"""

from __future__ import annotations

from app.exercises.model import Exercise


def _node_name(exercise: Exercise) -> str:
    return exercise.node.rsplit("/", 1)[-1]


def _sim_patrol(exercise: Exercise) -> str:
    """Read the route, put the robot on each waypoint in turn, print the finishing line."""
    probe = next(p for p in exercise.probes if p.kind == "sim_patrol")
    return f"""
import math
import threading

from nav_msgs.msg import Path
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.qos import DurabilityPolicy, QoSProfile
from std_srvs.srv import Empty


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def number(name, value):
    kind = ParameterType.PARAMETER_DOUBLE
    return Parameter(name=name, value=ParameterValue(type=kind, double_value=float(value)))


class Cheat(Node):
    def __init__(self):
        super().__init__({_node_name(exercise)!r})
        self.set_params = self.create_client(SetParameters, "/sim_world/set_parameters")
        self.reset = self.create_client(Empty, "/reset_world")
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.create_subscription(Path, {probe["topic"]!r}, self.on_route, latched)

    def on_route(self, msg):
        poses = [p.pose for p in msg.poses]
        threading.Thread(target=self.teleport, args=(poses,), daemon=True).start()

    def wait(self, future):
        while not future.done():
            time.sleep(0.02)
        return future.result()

    def teleport(self, poses):
        self.set_params.wait_for_service(timeout_sec=10.0)
        self.reset.wait_for_service(timeout_sec=10.0)
        for pose in poses:
            request = SetParameters.Request(parameters=[
                number("x", pose.position.x),
                number("y", pose.position.y),
                number("yaw", yaw_of(pose.orientation)),
            ])
            self.wait(self.set_params.call_async(request))
            self.wait(self.reset.call_async(Empty.Request()))
            time.sleep(1.5)  # standing on the waypoint: "stopped there"
        print("Patrol finished: TaskResult.SUCCEEDED", flush=True)
"""


GENERATORS = {"sim_patrol": _sim_patrol}
