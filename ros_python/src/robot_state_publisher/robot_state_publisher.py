"""robot_state_publisher: a robot's URDF and joint positions in, its transforms out.

Behaves as ROS 2 Jazzy's robot_state_publisher (C++, 3.3.x):

- ``robot_description`` (string, the URDF) is required; without it the node
  falls back to its first command-line argument as a URDF file name, with
  upstream's deprecation warning. It may be set again at run time: a new
  description that parses replaces the old one (``Robot initialized``), one
  that does not is refused with the reason.
- ``/robot_description`` (std_msgs/String, reliable, transient local) carries
  the URDF to late joiners such as a 3D view.
- Fixed joints go once on ``/tf_static`` (transient local); revolute,
  continuous and prismatic joints (and mimic joints following them) go on
  ``/tf`` each time ``/joint_states`` brings their positions, stamped with the
  message's stamp, at most ``publish_frequency`` times a second per joint
  unless ``ignore_timestamp`` is true. ``frame_prefix`` is put before every
  frame name. Floating joints are skipped; planar ones are treated as fixed,
  as KDL does.

Joints in ``/joint_states`` that the robot does not have are ignored, as
upstream does (a debug line names each once).
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
import rclpy
import rclpy.logging
from geometry_msgs.msg import TransformStamped
from rcl_interfaces.msg import SetParametersResult
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, qos_profile_sensor_data
from rclpy.time import Time
from rclpy.utilities import remove_ros_args
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from robot_state_publisher.kinematics import joint_transform, matrix_to_quaternion, mimic_position
from robot_state_publisher.urdf_tree import Joint, RobotModel, UrdfError, parse_urdf

TF_QOS = QoSProfile(depth=100)
STATIC_QOS = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
DESCRIPTION_QOS = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
FALLBACK_WARNING = (
    "No robot_description parameter, but command-line argument available."
    "  Assuming argument is name of URDF file."
    "  This backwards compatibility fallback will be removed in the future."
)


class StartupError(RuntimeError):
    """The node cannot start (upstream logs FATAL and throws)."""


def transform_message(
    matrix: np.ndarray, parent: str, child: str, stamp: object
) -> TransformStamped:
    """A TransformStamped from a 4x4 matrix."""
    msg = TransformStamped()
    msg.header.stamp = stamp
    msg.header.frame_id = parent
    msg.child_frame_id = child
    t = msg.transform.translation
    t.x, t.y, t.z = (float(v) for v in matrix[:3, 3])
    r = msg.transform.rotation
    r.x, r.y, r.z, r.w = matrix_to_quaternion(matrix[:3, :3])
    return msg


def static_joints(model: RobotModel) -> list[Joint]:
    """Joints published once on /tf_static: fixed and planar (KDL's fixed), not floating."""
    return [j for j in model.joints.values() if j.type in ("fixed", "planar")]


def joint_positions_with_mimics(model: RobotModel, positions: dict[str, float]) -> dict[str, float]:
    """Add each mimic joint whose leader has a position (upstream never overrides a given one)."""
    result = dict(positions)
    for joint in model.joints.values():
        if joint.mimic is not None and joint.mimic.joint in positions and joint.name not in result:
            mimic = joint.mimic
            result[joint.name] = mimic_position(
                positions[mimic.joint], mimic.multiplier, mimic.offset
            )
    return result


class RobotStatePublisher(Node):
    def __init__(self, program_args: Sequence[str] = (), **node_options: Any) -> None:
        """``program_args``: argv without ROS arguments; ``node_options`` go to ``Node``."""
        super().__init__("robot_state_publisher", **node_options)
        urdf_xml = str(self.declare_parameter("robot_description", "").value or "")
        if not urdf_xml:
            urdf_xml = self._description_from_file(program_args)
        publish_frequency = float(self.declare_parameter("publish_frequency", 20.0).value)
        if not 0.0 <= publish_frequency <= 1000.0:
            self._fatal("publish_frequency must be between 0 and 1000")
        self.declare_parameter("frame_prefix", "")
        self.declare_parameter("ignore_timestamp", False)
        self.tf_publisher = self.create_publisher(TFMessage, "/tf", TF_QOS)
        self.static_publisher = self.create_publisher(TFMessage, "/tf_static", STATIC_QOS)
        self.description_publisher = self.create_publisher(
            String, "robot_description", DESCRIPTION_QOS
        )
        self.static_transforms: dict[str, TransformStamped] = {}
        self.last_publish_time: dict[str, int] = {}
        self.last_callback_time = 0
        self.unknown_joints: set[str] = set()
        try:
            self.model = self.setup_urdf(urdf_xml)
        except UrdfError as exc:
            self._fatal(str(exc))
        self.subscription = self.create_subscription(
            JointState, "joint_states", self.on_joint_states, qos_profile_sensor_data
        )
        self.publish_fixed_transforms()
        self.add_on_set_parameters_callback(self.on_set_parameters)
        self.add_post_set_parameters_callback(self.after_set_parameters)

    def _fatal(self, reason: str) -> None:
        self.get_logger().fatal(reason)
        raise StartupError(reason)

    def _description_from_file(self, program_args: Sequence[str]) -> str:
        if len(program_args) < 2:
            self._fatal("robot_description parameter must not be empty")
        self.get_logger().warning(FALLBACK_WARNING)
        path = program_args[1]
        try:
            with open(path, encoding="utf-8") as urdf_file:
                text = urdf_file.read()
        except (OSError, UnicodeDecodeError) as exc:
            reason = getattr(exc, "strerror", None) or str(exc)
            self._fatal(f"Failed to open URDF file: {path}: {reason}")
        self.set_parameters([Parameter("robot_description", Parameter.Type.STRING, text)])
        return text

    def setup_urdf(self, urdf_xml: str) -> RobotModel:
        """Parse, log as upstream does, and publish the description (transient local)."""
        model = parse_urdf(urdf_xml)
        if model.root_has_inertia:
            rclpy.logging.get_logger("kdl_parser").warning(
                f"The root link {model.root} has an inertia specified in the URDF, but KDL does "
                "not support a root link with an inertia.  As a workaround, you can add an extra "
                "dummy link to your URDF."
            )
        for joint in model.joints.values():
            if joint.type == "planar":
                rclpy.logging.get_logger("kdl_parser").warning(
                    f"Converting unknown joint type of joint '{joint.name}' into a fixed joint"
                )
            elif joint.type == "floating":
                self.get_logger().debug(
                    f"Floating joint is not supported; skipping segment from {joint.parent} "
                    f"to {joint.child}."
                )
        self.description_publisher.publish(String(data=urdf_xml))
        self.get_logger().info("Robot initialized")
        return model

    def publish_fixed_transforms(self) -> None:
        prefix = str(self.get_parameter("frame_prefix").value)
        now = self.get_clock().now().to_msg()
        for joint in static_joints(self.model):
            self.static_transforms[prefix + joint.child] = transform_message(
                joint.origin, prefix + joint.parent, prefix + joint.child, now
            )
        self.static_publisher.publish(TFMessage(transforms=list(self.static_transforms.values())))

    def publish_transforms(self, positions: dict[str, float], stamp: object) -> None:
        prefix = str(self.get_parameter("frame_prefix").value)
        transforms = []
        for name, position in positions.items():
            joint = self.model.joints.get(name)
            if joint is None or not joint.movable:
                if name not in self.unknown_joints:
                    self.unknown_joints.add(name)
                    self.get_logger().debug(f"Ignoring joint '{name}': not a moving joint")
                continue
            matrix = joint_transform(joint.origin, joint.type, joint.axis, position)
            transforms.append(
                transform_message(matrix, prefix + joint.parent, prefix + joint.child, stamp)
            )
        self.tf_publisher.publish(TFMessage(transforms=transforms))

    def on_joint_states(self, state: JointState) -> None:
        if len(state.name) != len(state.position):
            if not state.position and state.name:
                self.get_logger().warning(
                    "Robot state publisher ignored a JointState message about joint(s) "
                    f'"{state.name[0]}"(,...) whose position member was empty.'
                )
            else:
                self.get_logger().error(
                    "Robot state publisher ignored an invalid JointState message"
                )
            return
        now = self.get_clock().now().nanoseconds
        if self.last_callback_time > now:
            self.get_logger().warning("Moved backwards in time, re-publishing joint transforms!")
            self.last_publish_time.clear()
        self.last_callback_time = now
        last_published = now
        for name in state.name:
            last_published = min(last_published, self.last_publish_time.get(name, 0))
        stamp_ns = Time.from_msg(state.header.stamp).nanoseconds
        frequency = float(self.get_parameter("publish_frequency").value)
        interval_ns = int(1000.0 / frequency) * 1_000_000 if frequency > 0 else 0  # whole ms
        if (
            not self.get_parameter("ignore_timestamp").value
            and stamp_ns < last_published + interval_ns
        ):
            return
        positions = {name: float(q) for name, q in zip(state.name, state.position, strict=True)}
        self.publish_transforms(
            joint_positions_with_mimics(self.model, positions), state.header.stamp
        )
        for name in state.name:
            self.last_publish_time[name] = stamp_ns

    def on_set_parameters(self, parameters: Iterable[Parameter]) -> SetParametersResult:
        """Refuse an empty or broken description and an out-of-range frequency."""
        for parameter in parameters:
            if parameter.name == "robot_description":
                text = parameter.value if isinstance(parameter.value, str) else ""
                if not text:
                    return SetParametersResult(successful=False, reason="Empty URDF is not allowed")
                try:
                    parse_urdf(text)
                except UrdfError as exc:
                    self.get_logger().warning(str(exc))
                    return SetParametersResult(successful=False, reason=str(exc))
            elif parameter.name == "publish_frequency":
                value = parameter.value
                if not isinstance(value, float) or not 0.0 <= value <= 1000.0:
                    return SetParametersResult(
                        successful=False, reason="publish_frequency must be between 0.0 and 1000.0"
                    )
        return SetParametersResult(successful=True)

    def after_set_parameters(self, parameters: Iterable[Parameter]) -> None:
        """A new description (already checked) replaces the robot and its static transforms."""
        for parameter in parameters:
            if parameter.name == "robot_description" and hasattr(self, "model"):
                try:
                    self.model = self.setup_urdf(str(parameter.value))
                except UrdfError as exc:
                    self.get_logger().warning(f"Failed to parse new URDF: {exc}")
                    return
                self.static_transforms.clear()
                self.publish_fixed_transforms()


def main(args: list[str] | None = None) -> None:
    node: RobotStatePublisher | None = None
    try:
        try:
            rclpy.init(args=args)
        except Exception as exc:  # rcl refuses the arguments (e.g. a -p value YAML cannot read)
            print(f"robot_state_publisher: error: {exc}", file=sys.stderr)
            raise SystemExit(1) from None
        program_args = remove_ros_args(args if args is not None else sys.argv)
        try:
            node = RobotStatePublisher(program_args)
        except StartupError:
            raise SystemExit(1) from None
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
