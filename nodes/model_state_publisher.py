"""model_state_publisher: robot_state_publisher given a URDF or xacro file, as a launch file does.

The URDF tutorials' ``display.launch.py`` reads ``model:=FILE`` (running
xacro on it) and hands the text to robot_state_publisher as its
``robot_description`` parameter. This node does the same with its first
argument (default: the unit-13 arm, ``nodes/robots/robotic_arm/robot.urdf``)
and is then ROS 2's robot_state_publisher (our Python version), node name
``/robot_state_publisher``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import rclpy
from rclpy.parameter import Parameter
from rclpy.utilities import remove_ros_args
from robot_state_publisher.robot_state_publisher import RobotStatePublisher, StartupError

from nodes.common.run import init_ros, ros_started, stopped_quietly

ARM_URDF = Path(__file__).with_name("robots") / "robotic_arm" / "robot.urdf"


def read_description(path: Path) -> str:
    """The URDF text of ``path``; a ``.xacro`` file is expanded by xacro first."""
    if path.suffix == ".xacro":
        import xacro

        return str(xacro.process_file(str(path)).toxml())
    return path.read_text(encoding="utf-8")


def main(args: list[str] | None = None) -> None:
    node: RobotStatePublisher | None = None
    try:
        with stopped_quietly():  # Ctrl+C or SIGTERM, even during start-up: leave quietly
            init_ros(args)
            words = remove_ros_args(args if args is not None else sys.argv)
            path = Path(words[1]) if len(words) > 1 else ARM_URDF
            try:
                text = read_description(path)
            except Exception as exc:  # a missing file, bad xacro: one line, exit 2
                print(f"model_state_publisher: error: cannot read {path}: {exc}", file=sys.stderr)
                raise SystemExit(2) from None
            description = Parameter("robot_description", Parameter.Type.STRING, text)
            try:
                node = RobotStatePublisher(parameter_overrides=[description])
            except StartupError:
                raise SystemExit(1) from None
            ros_started()
            rclpy.spin(node)
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
