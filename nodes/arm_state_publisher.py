"""arm_state_publisher: robot_state_publisher for the unit-13 robotic_arm.

It is ROS 2's robot_state_publisher (our Python version) started with the
arm's URDF (``nodes/robots/robotic_arm/robot.urdf``) as its
``robot_description`` parameter, as a launch file would pass it; the arm's
``/joint_states`` then become ``/tf``: base_link -> turret -> upper_arm ->
forearm -> gripper -> tool0.
"""

from pathlib import Path

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.parameter import Parameter
from robot_state_publisher.robot_state_publisher import RobotStatePublisher, StartupError

URDF = Path(__file__).with_name("robots") / "robotic_arm" / "robot.urdf"


def main(args: list[str] | None = None) -> None:
    node: RobotStatePublisher | None = None
    try:
        rclpy.init(args=args)
        description = Parameter("robot_description", Parameter.Type.STRING, URDF.read_text())
        try:
            node = RobotStatePublisher(parameter_overrides=[description])
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
