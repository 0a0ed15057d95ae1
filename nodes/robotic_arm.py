"""robotic_arm: a simulated 4-joint arm that reaches for targets.

It listens on ``/pos_in_robot_base_frame`` (a point in ``base_link``), solves
inverse kinematics (which joint angles put the gripper there?) and moves its
joints smoothly towards the answer, never faster than ``max_joint_speed``
rad/s. It publishes, ``rate`` times a second:

- ``/joint_states`` (``sensor_msgs/JointState``): joint names and angles, the
  standard message robot_state_publisher and rviz read;
- ``/end_effector_pose`` (``geometry_msgs/PoseStamped``): where the gripper
  is, computed from the joint angles by forward kinematics.

A target the arm cannot reach is not ignored silently: it logs a warning
saying why and publishes the reason on ``/arm_status`` (``std_msgs/String``),
which also reports "moving" and "reached" as the arm works.

The geometry (link lengths 0.10 / 0.30 / 0.25 / 0.08 m, joint limits) and the
analytic IK are documented in ``nodes/common/arm_kinematics.py``.
"""

import math

import numpy as np
from geometry_msgs.msg import PointStamped, PoseStamped
from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_msgs.msg import String

from nodes.common.arm_kinematics import (
    JOINT_NAMES,
    Unreachable,
    forward_kinematics,
    inverse_kinematics,
    step_towards,
)
from nodes.common.frames import matrix_to_quaternion
from nodes.common.run import spin_node

HOME = (0.0, math.radians(60.0), math.radians(-110.0), math.radians(-40.0))


class RoboticArm(Node):
    def __init__(self) -> None:
        super().__init__("robotic_arm")
        self.declare_parameter("rate", 25.0)  # Hz
        self.declare_parameter(
            "max_joint_speed",
            1.5,
            # A range makes ROS refuse 0, a negative or NaN speed, which cannot move the arm.
            ParameterDescriptor(
                description="rad/s, the fastest a joint may turn",
                floating_point_range=[FloatingPointRange(from_value=0.01, to_value=10.0)],
            ),
        )
        self.declare_parameter("base_frame", "base_link")
        self.joints = np.array(HOME)
        self.goal = self.joints.copy()
        self.target: tuple[float, float, float] | None = None
        self.state = "idle"
        self.joint_publisher = self.create_publisher(JointState, "joint_states", 10)
        self.pose_publisher = self.create_publisher(PoseStamped, "end_effector_pose", 10)
        self.status_publisher = self.create_publisher(String, "arm_status", 10)
        self.subscription = self.create_subscription(
            PointStamped, "pos_in_robot_base_frame", self.on_target, 10
        )
        self.period = 1.0 / float(self.get_parameter("rate").value)
        self.timer = self.create_timer(self.period, self.on_timer)

    def report(self, text: str) -> None:
        self.status_publisher.publish(String(data=text))

    def on_target(self, msg: PointStamped) -> None:
        target = (msg.point.x, msg.point.y, msg.point.z)
        if target == self.target:
            return  # the same target again: keep going
        try:
            goal = inverse_kinematics(target, seed_yaw=float(self.joints[0]))
        except Unreachable as exc:
            self.get_logger().warning(str(exc))
            self.report(f"unreachable: {exc}")
            return
        self.target = target
        self.goal = goal
        self.state = "moving"
        x, y, z = target
        self.report(f"moving to ({x:.3f}, {y:.3f}, {z:.3f})")

    def on_timer(self) -> None:
        max_step = float(self.get_parameter("max_joint_speed").value) * self.period
        self.joints = step_towards(self.joints, self.goal, max_step)
        arrived = np.allclose(self.joints, self.goal, atol=1e-9)
        if self.state == "moving" and self.target is not None and arrived:
            self.state = "reached"
            x, y, z = self.target
            self.report(f"reached ({x:.3f}, {y:.3f}, {z:.3f})")
            self.get_logger().info(f"reached ({x:.3f}, {y:.3f}, {z:.3f})")
        now = self.get_clock().now().to_msg()
        frame = self.get_parameter("base_frame").value
        joint_state = JointState()
        joint_state.header.stamp = now
        joint_state.name = list(JOINT_NAMES)
        joint_state.position = [float(q) for q in self.joints]
        self.joint_publisher.publish(joint_state)
        pose = forward_kinematics(self.joints)
        msg = PoseStamped()
        msg.header.stamp = now
        msg.header.frame_id = frame
        msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = (
            float(v) for v in pose.position
        )
        q = matrix_to_quaternion(pose.rotation)
        msg.pose.orientation.x, msg.pose.orientation.y = q[0], q[1]
        msg.pose.orientation.z, msg.pose.orientation.w = q[2], q[3]
        self.pose_publisher.publish(msg)


def main(args=None) -> None:
    spin_node(RoboticArm, args)


if __name__ == "__main__":
    main()
