"""coordinate_transform_tf2: the same job as coordinate_transform, done the ROS 2 way with tf2.

``coordinate_transform`` keeps the camera's pose in six parameters of its
own and multiplies by a 4x4 matrix it builds itself. Here the node knows
nothing about the camera: the pose is a transform on ``/tf_static``
(``base_link -> camera``, published once by a static_transform_publisher or
by whoever mounts the camera), and a tf2 Buffer, filled by a
TransformListener, answers "where is this point in base_link?":

    point_in_base = self.tf_buffer.transform(point_in_camera, "base_link")

``transform`` reads the point's ``header.frame_id`` ("camera") and
``header.stamp``, looks up ``base_link <- camera`` at that stamp (a moving
camera is looked up where it was when it saw the point), and applies it. A
missing frame is an exception that says which frame, not a silently wrong
point.

Topics: ``/pos_in_cam_frame`` in, ``/pos_in_robot_base_frame`` out (the
same as coordinate_transform, so it replaces it). To run both side by side,
remap the output: ``--ros-args -r
pos_in_robot_base_frame:=pos_in_robot_base_frame_tf2``. Parameter
``base_frame`` (default ``base_link``): the frame points are written in.
"""

import tf2_geometry_msgs  # noqa: F401  (registers PointStamped with tf2's transform())
from geometry_msgs.msg import PointStamped
from rclpy.node import Node
from tf2_ros import TransformException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener

from nodes.common.run import spin_node


class CoordinateTransformTf2(Node):
    def __init__(self) -> None:
        super().__init__("coordinate_transform_tf2")
        self.declare_parameter("base_frame", "base_link")
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.publisher = self.create_publisher(PointStamped, "pos_in_robot_base_frame", 10)
        self.subscription = self.create_subscription(
            PointStamped, "pos_in_cam_frame", self.on_camera_point, 10
        )

    def on_camera_point(self, msg: PointStamped) -> None:
        base_frame = self.get_parameter("base_frame").get_parameter_value().string_value
        try:
            out = self.tf_buffer.transform(msg, base_frame)
        except TransformException as ex:
            self.get_logger().info(
                f"Could not transform {msg.header.frame_id} to {base_frame}: {ex}",
                throttle_duration_sec=2.0,
            )
            return
        self.publisher.publish(out)
        p = out.point
        self.get_logger().debug(
            f"{msg.header.frame_id} -> {base_frame} ({p.x:.3f}, {p.y:.3f}, {p.z:.3f})"
        )


def main(args=None) -> None:
    spin_node(CoordinateTransformTf2, args)


if __name__ == "__main__":
    main()
