"""joint_state_publisher: a JointState for every movable joint of the robot description.

As ROS 2 Jazzy's joint_state_publisher: it reads the URDF from the
``robot_description`` topic (transient local, so it may start before or
after robot_state_publisher) or from a file named as its first argument,
then publishes ``joint_states`` ``rate`` times a second (10) with one
position per movable joint in document order: ``zeros.<joint>`` if given,
else 0, or the middle of the limits when 0 is outside them. Mimic joints
follow their leader (``use_mimic_tags``). JointState messages on the topics
of ``source_list`` (a driver, or the dashboard's sliders) set the joints
they name; ``delta`` > 0 sweeps every joint back and forth on its own.

The choice of start values and the mimic arithmetic are plain functions.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import Any

import rclpy
from rclpy.exceptions import ParameterUninitializedException
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile
from rclpy.utilities import remove_ros_args
from robot_state_publisher.urdf_tree import Joint, RobotModel, UrdfError, parse_urdf
from sensor_msgs.msg import JointState
from std_msgs.msg import String

DESCRIPTION_QOS = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)


@dataclass
class FreeJoint:
    """A joint a user sets: its range (continuous: -pi..pi) and current position."""

    lower: float
    upper: float
    position: float
    continuous: bool = False
    forward: bool = True


def start_position(lower: float, upper: float, zero: float | None = None) -> float:
    """``zero`` if given, else 0, or the middle of the range when 0 lies outside it."""
    if zero is not None:
        return zero
    if lower > 0.0 or upper < 0.0:
        return (lower + upper) / 2.0
    return 0.0


def free_joint(joint: Joint, zero: float | None = None) -> FreeJoint:
    if joint.type == "continuous" or joint.lower is None or joint.upper is None:
        return FreeJoint(-math.pi, math.pi, start_position(-math.pi, math.pi, zero), True)
    return FreeJoint(joint.lower, joint.upper, start_position(joint.lower, joint.upper, zero))


def mimic_chain(model: RobotModel, name: str) -> tuple[str, float, float]:
    """(free leader, factor, offset) of a mimic joint, following mimics of mimics."""
    factor, offset, seen = 1.0, 0.0, [name]
    joint = model.joints[name]
    while joint.mimic is not None:
        offset += factor * joint.mimic.offset
        factor *= joint.mimic.multiplier
        if joint.mimic.joint in seen:
            raise UrdfError(
                f"Found an infinite recursive mimic chain: {seen + [joint.mimic.joint]}"
            )
        seen.append(joint.mimic.joint)
        joint = model.joints[joint.mimic.joint]
    return joint.name, factor, offset


def sweep(joint: FreeJoint, delta: float) -> None:
    """One step of ``delta``: back and forth between the limits, round and round if continuous."""
    if joint.forward:
        joint.position += delta
        if joint.position > joint.upper:
            if joint.continuous:
                joint.position = joint.lower
            else:
                joint.position, joint.forward = joint.upper, False
    else:
        joint.position -= delta
        if joint.position < joint.lower:
            joint.position, joint.forward = joint.lower, True


class JointStatePublisher(Node):
    def __init__(self, description_file: str | None = None) -> None:
        super().__init__(
            "joint_state_publisher", automatically_declare_parameters_from_overrides=True
        )
        defaults: tuple[tuple[str, object], ...] = (
            ("publish_default_positions", True),
            ("rate", 10),
            ("source_list", Parameter.Type.STRING_ARRAY),  # declared, empty
            ("use_mimic_tags", True),
            ("delta", 0.0),
        )
        for name, default in defaults:
            if not self.has_parameter(name):  # given on the command line: declared already
                self.declare_parameter(name, default)
        zeros: dict[str, Any] = dict(self.get_parameters_by_prefix("zeros"))
        self.zeros = {name: float(parameter.value) for name, parameter in zeros.items()}
        self.model: RobotModel | None = None
        self.free: dict[str, FreeJoint] = {}
        self.order: list[str] = []
        if description_file is not None:
            with open(description_file, encoding="utf-8") as description:
                self.configure_robot(description.read())
        else:
            self.get_logger().info(
                "Waiting for robot_description to be published on the robot_description topic..."
            )
        self.description_subscription = self.create_subscription(
            String, "robot_description", self.on_robot_description, DESCRIPTION_QOS
        )
        self.source_subscriptions = [
            self.create_subscription(JointState, str(topic), self.on_source_state, 10)
            for topic in self.source_list()
        ]
        self.publisher = self.create_publisher(JointState, "joint_states", 10)
        rate = float(self.get_parameter("rate").value)
        if not math.isfinite(rate) or rate <= 0.0:
            raise ValueError(f"rate must be a positive number of Hz, got {rate}")
        self.timer = self.create_timer(1.0 / rate, self.on_timer)

    def source_list(self) -> list[str]:
        """The source topics; none when the parameter was declared without a value."""
        try:
            return list(self.get_parameter("source_list").value or [])
        except ParameterUninitializedException:
            return []

    def configure_robot(self, description: str) -> None:
        model = parse_urdf(description)
        use_mimic = bool(self.get_parameter("use_mimic_tags").value)
        for joint in model.movable_joints():
            if use_mimic and joint.mimic is not None:
                mimic_chain(model, joint.name)  # refuse a loop now, not at every tick
        self.model = model
        self.order = [j.name for j in model.movable_joints()]
        self.free = {
            j.name: free_joint(j, self.zeros.get(j.name))
            for j in model.movable_joints()
            if not (use_mimic and j.mimic is not None)
        }

    def on_robot_description(self, msg: String) -> None:
        try:
            self.configure_robot(msg.data)
        except UrdfError as exc:
            self.get_logger().warning(str(exc))

    def on_source_state(self, msg: JointState) -> None:
        for index, name in enumerate(msg.name):
            if name in self.free and index < len(msg.position):
                position = float(msg.position[index])
                if math.isfinite(position):
                    self.free[name].position = position

    def positions(self) -> dict[str, float]:
        """Every movable joint's position, in the description's order."""
        result: dict[str, float] = {}
        for name in self.order:
            if name in self.free:
                result[name] = self.free[name].position
            elif self.model is not None:
                leader, factor, offset = mimic_chain(self.model, name)
                result[name] = self.free[leader].position * factor + offset
        return result

    def on_timer(self) -> None:
        delta = float(self.get_parameter("delta").value)
        if delta > 0.0:
            for joint in self.free.values():
                sweep(joint, delta)
        positions = self.positions()
        if not positions:
            return  # upstream publishes only non-empty messages
        msg = JointState()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.name = list(positions)
        if self.get_parameter("publish_default_positions").value:
            msg.position = [float(v) for v in positions.values()]
        self.publisher.publish(msg)


def main(args: list[str] | None = None) -> None:
    node: JointStatePublisher | None = None
    try:
        rclpy.init(args=args)
        program_args = remove_ros_args(args if args is not None else sys.argv)
        try:
            node = JointStatePublisher(program_args[1] if len(program_args) > 1 else None)
        except (ValueError, OSError) as exc:
            print(f"joint_state_publisher: error: {exc}", file=sys.stderr)
            raise SystemExit(2) from None
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
