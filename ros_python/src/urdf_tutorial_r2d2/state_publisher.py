"""state_publisher: the tutorial's R2-D2 walks a circle, nods, turns its head, raises a periscope.

As the "Using URDF with robot_state_publisher (Python)" tutorial's node: 30
times a second it publishes ``joint_states`` for ``swivel``, ``tilt`` and
``periscope`` (robot_state_publisher turns them into ``/tf``) and broadcasts
``odom -> axis``: the robot on a circle of 2 m radius at 0.7 m height,
facing along the circle. Tilt swings between -0.5 and 0 rad, the
periscope between 0 and 0.2 m, the head turns one degree a step. Written
with the tutorial's imports (``tf2_ros.TransformBroadcaster``).
"""

from __future__ import annotations

import math

import rclpy
from geometry_msgs.msg import Quaternion, TransformStamped
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState
from tf2_ros import TransformBroadcaster

DEGREE = math.pi / 180.0
RATE_HZ = 30.0


def euler_to_quaternion(roll: float, pitch: float, yaw: float) -> Quaternion:
    """Fixed-axis roll, pitch, yaw as a quaternion, the maths the tutorial writes out."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return Quaternion(
        x=sr * cp * cy - cr * sp * sy,
        y=cr * sp * cy + sr * cp * sy,
        z=cr * cp * sy - sr * sp * cy,
        w=cr * cp * cy + sr * sp * sy,
    )


class StatePublisher(Node):
    def __init__(self) -> None:
        super().__init__("state_publisher")
        qos_profile = QoSProfile(depth=10)
        self.joint_pub = self.create_publisher(JointState, "joint_states", qos_profile)
        self.broadcaster = TransformBroadcaster(self, qos=qos_profile)
        self.get_logger().info(f"{self.get_name()} started")
        self.tilt, self.tilt_step = 0.0, DEGREE
        self.height, self.height_step = 0.0, 0.005
        self.swivel, self.angle = 0.0, 0.0
        self.timer = self.create_timer(1.0 / RATE_HZ, self.on_timer)

    def on_timer(self) -> None:
        now = self.get_clock().now().to_msg()
        joint_state = JointState()
        joint_state.header.stamp = now
        joint_state.name = ["swivel", "tilt", "periscope"]
        joint_state.position = [self.swivel, self.tilt, self.height]
        odom_trans = TransformStamped()
        odom_trans.header.stamp = now
        odom_trans.header.frame_id = "odom"
        odom_trans.child_frame_id = "axis"
        odom_trans.transform.translation.x = math.cos(self.angle) * 2.0
        odom_trans.transform.translation.y = math.sin(self.angle) * 2.0
        odom_trans.transform.translation.z = 0.7
        odom_trans.transform.rotation = euler_to_quaternion(0.0, 0.0, self.angle + math.pi / 2)
        self.joint_pub.publish(joint_state)
        self.broadcaster.sendTransform(odom_trans)
        # Next pose: swing the tilt and the periscope between their limits, turn on.
        self.tilt += self.tilt_step
        if self.tilt < -0.5 or self.tilt > 0.0:
            self.tilt_step *= -1
        self.height += self.height_step
        if self.height > 0.2 or self.height < 0.0:
            self.height_step *= -1
        self.swivel += DEGREE
        self.angle += DEGREE / 4


def main(args: list[str] | None = None) -> None:
    node: StatePublisher | None = None
    try:
        rclpy.init(args=args)
        node = StatePublisher()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
