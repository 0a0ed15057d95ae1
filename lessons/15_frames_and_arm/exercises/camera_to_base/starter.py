"""Exercise: re-express camera-frame points in the robot's base frame."""

import math

import numpy as np
import rclpy
from geometry_msgs.msg import PointStamped
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

# Where the camera is mounted, in the base frame (metres and radians): parameters, so
# the same node serves a camera mounted elsewhere (ros2 param set /cam_to_base camera_x 0.4).
MOUNT = {
    "camera_x": 0.30,
    "camera_y": -0.20,
    "camera_z": 0.65,
    "camera_roll": -2.6,
    "camera_pitch": 0.1,
    "camera_yaw": 0.5,
}


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def transform_from_mount(m):
    """The 4x4 T_base_camera for the mount m (the six camera_* values, by name)."""
    # TODO 1: the rotation Rz(m["camera_yaw"]) @ Ry(m["camera_pitch"]) @ Rx(m["camera_roll"])
    #         in the top-left 3x3 block, the camera position (camera_x, _y, _z) in the
    #         last column.
    T_base_camera = np.eye(4)
    return T_base_camera


class CamToBase(Node):
    def __init__(self):
        super().__init__("cam_to_base")
        for name, value in MOUNT.items():
            self.declare_parameter(name, value)
        self.publisher = self.create_publisher(PointStamped, "pos_in_robot_base_frame", 10)
        self.subscription = self.create_subscription(
            PointStamped, "pos_in_cam_frame", self.on_point, 10
        )

    def camera_transform(self):
        """T_base_camera from the mount parameters as they are now."""
        return transform_from_mount({name: self.get_parameter(name).value for name in MOUNT})

    def on_point(self, msg):
        # TODO 2: p_base = self.camera_transform() @ (x, y, z, 1); publish its first
        #         three values with the input's stamp and frame_id "base_link".
        out = PointStamped()
        out.header = msg.header
        out.point = msg.point
        self.publisher.publish(out)


def main():
    rclpy.init()
    node = CamToBase()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
