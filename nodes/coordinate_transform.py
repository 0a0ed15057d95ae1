"""coordinate_transform: re-express a point seen by the camera in the robot's frame.

The camera reports positions relative to itself; the arm needs them relative
to its own base (``base_link``). Both describe the same physical point: what
changes is the frame. If we know where the camera is mounted (its *pose* in
the base frame, a rotation and a translation), one 4x4 homogeneous transform
converts any point: ``p_base = T_base_camera @ p_camera``.

The camera pose is six parameters, in metres and radians, in the base frame:
``camera_x``, ``camera_y``, ``camera_z`` and ``camera_roll``, ``camera_pitch``,
``camera_yaw`` (roll about x, then pitch about y, then yaw about z, all about
the fixed base axes; ROS enforces a range, +-10 m and +-2 pi). The default
puts the camera 0.25 m in front of the arm and 0.7 m above the table, looking
straight down (unrotated, the optical z axis is the base's z, pointing up;
roll = pi about x turns it to point down).
Change one while the node runs and the next point uses it:
``ros2 param set /coordinate_transform camera_z 0.8``.

ROS concepts shown: a node that is both a subscriber and a publisher (a
"relay" that transforms data), parameters read on every message, and
``header.frame_id`` changing from "camera" to "base_link". In a full ROS
install tf2 would hold this transform; here the math is in
``nodes/common/frames.py``.
"""

import math

from geometry_msgs.msg import PointStamped
from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor
from rclpy.node import Node

from nodes.common.frames import pose_to_matrix, transform_points
from nodes.common.run import spin_node

DEFAULT_CAMERA_POSE = {
    "camera_x": 0.25,
    "camera_y": 0.0,
    "camera_z": 0.70,
    "camera_roll": math.pi,
    "camera_pitch": 0.0,
    "camera_yaw": 0.0,
}

POSITION_LIMIT_M = 10.0
ANGLE_LIMIT_RAD = 2 * math.pi


def pose_descriptor(name: str) -> ParameterDescriptor:
    """A range for one pose parameter: ROS then refuses NaN, infinity and the absurd."""
    angle = name.endswith(("roll", "pitch", "yaw"))
    limit = ANGLE_LIMIT_RAD if angle else POSITION_LIMIT_M
    return ParameterDescriptor(
        description=f"camera pose in the base frame ({'radians' if angle else 'metres'})",
        floating_point_range=[FloatingPointRange(from_value=-limit, to_value=limit)],
    )


class CoordinateTransform(Node):
    def __init__(self) -> None:
        super().__init__("coordinate_transform")
        for name, value in DEFAULT_CAMERA_POSE.items():
            self.declare_parameter(name, value, pose_descriptor(name))
        self.declare_parameter("base_frame", "base_link")
        self.publisher = self.create_publisher(PointStamped, "pos_in_robot_base_frame", 10)
        self.subscription = self.create_subscription(
            PointStamped, "pos_in_cam_frame", self.on_camera_point, 10
        )

    def camera_pose(self):
        """T_base_camera from the current parameter values."""
        values = [float(self.get_parameter(name).value) for name in DEFAULT_CAMERA_POSE]
        return pose_to_matrix(*values)

    def on_camera_point(self, msg: PointStamped) -> None:
        p_cam = (msg.point.x, msg.point.y, msg.point.z)
        x, y, z = transform_points(self.camera_pose(), p_cam)
        out = PointStamped()
        out.header.stamp = msg.header.stamp  # the same moment, another frame
        out.header.frame_id = self.get_parameter("base_frame").value
        out.point.x, out.point.y, out.point.z = float(x), float(y), float(z)
        self.publisher.publish(out)
        self.get_logger().debug(f"camera {p_cam} -> base ({x:.3f}, {y:.3f}, {z:.3f})")


def main(args=None) -> None:
    spin_node(CoordinateTransform, args)


if __name__ == "__main__":
    main()
