"""joint_state_publisher: a JointState for every movable joint of the robot description.

As ROS 2 Jazzy's joint_state_publisher: it reads the URDF from the
``robot_description`` topic (transient local, so it may start before or
after robot_state_publisher), then publishes ``/joint_states`` ``rate``
times a second (10 Hz) with one position per free joint: 0, or the middle
of the limits when 0 is outside them. Mimic joints follow their leader. Values received on
the topics of ``source_list`` (JointState messages, e.g. a driver or
sliders in a browser) replace the defaults of the joints they name.

The maths of choosing start values lives in plain functions
(``initial_position``, ``positions_with_mimics``).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile
from robot_state_publisher.urdf_tree import Joint, RobotModel, UrdfError, parse_urdf
from sensor_msgs.msg import JointState
from std_msgs.msg import String

DESCRIPTION_QOS = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def initial_position(joint: Joint, zero: float | None = None) -> float:
    """0 (or ``zero``) when the limits allow it, else the middle of the limits."""
    value = 0.0 if zero is None else zero
    if joint.lower is None or joint.upper is None or joint.lower > joint.upper:
        return value
    if joint.lower <= value <= joint.upper:
        return value
    return (joint.lower + joint.upper) / 2.0


def free_joints(model: RobotModel) -> list[Joint]:
    """The joints a user sets: movable and not mimicking another joint."""
    return [j for j in model.movable_joints() if j.mimic is None]


def positions_with_mimics(model: RobotModel, free: Mapping[str, float]) -> dict[str, float]:
    """Every movable joint's position: the free ones, then each mimic from its leader."""
    result = dict(free)
    pending = [j for j in model.movable_joints() if j.mimic is not None]
    for _ in range(len(pending) + 1):  # a mimic of a mimic resolves on a later pass
        waiting = []
        for joint in pending:
            assert joint.mimic is not None
            if joint.mimic.joint in result:
                leader = result[joint.mimic.joint]
                result[joint.name] = leader * joint.mimic.multiplier + joint.mimic.offset
            else:
                waiting.append(joint)
        pending = waiting
    return {j.name: result[j.name] for j in model.movable_joints() if j.name in result}


class JointStatePublisher(Node):
    def __init__(self) -> None:
        super().__init__("joint_state_publisher")
        self.declare_parameter("rate", 10.0)
        self.declare_parameter("source_list", Parameter.Type.STRING_ARRAY)
        self.declare_parameter("use_mimic_tags", True)
        self.declare_parameter("publish_default_positions", True)
        self.model: RobotModel | None = None
        self.positions: dict[str, float] = {}
        self.publisher = self.create_publisher(JointState, "joint_states", 10)
        self.description_subscription = self.create_subscription(
            String, "robot_description", self.on_robot_description, DESCRIPTION_QOS
        )
        sources = self.get_parameter("source_list").value or []
        self.source_subscriptions = [
            self.create_subscription(JointState, str(topic), self.on_source_state, 10)
            for topic in sources
        ]
        rate = float(self.get_parameter("rate").value)
        if not math.isfinite(rate) or rate <= 0.0:
            raise ValueError(f"rate must be a positive number of Hz, got {rate}")
        self.timer = self.create_timer(1.0 / rate, self.on_timer)
        self.get_logger().info(
            "Waiting for robot_description to be published on the robot_description topic..."
        )

    def on_robot_description(self, msg: String) -> None:
        try:
            model = parse_urdf(msg.data)
        except UrdfError as exc:
            self.get_logger().error(f"Failed to parse the robot description: {exc}")
            return
        self.model = model
        old = self.positions
        self.positions = {j.name: old.get(j.name, initial_position(j)) for j in free_joints(model)}

    def set_position(self, joint: str, position: float) -> bool:
        """Set one free joint (clamped to its limits); False for a joint it does not have."""
        if self.model is None or joint not in self.positions or not math.isfinite(position):
            return False
        info = self.model.joints[joint]
        if info.lower is not None and info.upper is not None and info.lower <= info.upper:
            position = min(max(position, info.lower), info.upper)
        self.positions[joint] = position
        return True

    def on_source_state(self, msg: JointState) -> None:
        for name, position in zip(msg.name, msg.position, strict=False):
            self.set_position(name, float(position))

    def on_timer(self) -> None:
        if self.model is None:
            return
        msg = JointState()
        msg.header.stamp = self.get_clock().now().to_msg()
        if self.get_parameter("use_mimic_tags").value:
            positions = positions_with_mimics(self.model, self.positions)
        else:
            positions = dict(self.positions)
        msg.name = list(positions)
        if self.get_parameter("publish_default_positions").value:
            msg.position = [float(v) for v in positions.values()]
        self.publisher.publish(msg)


def main(args: list[str] | None = None) -> None:
    node: JointStatePublisher | None = None
    try:
        rclpy.init(args=args)
        try:
            node = JointStatePublisher()
        except ValueError as exc:
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
