"""Exercise: re-express camera-frame points in the robot's base frame."""

import math

import numpy as np
import rclpy
from geometry_msgs.msg import PointStamped
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

# Where the camera is mounted, in the base frame (metres and radians).
CAMERA_X, CAMERA_Y, CAMERA_Z = 0.30, -0.20, 0.65
CAMERA_ROLL, CAMERA_PITCH, CAMERA_YAW = -2.6, 0.1, 0.5


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class CamToBase(Node):
    def __init__(self):
        super().__init__("cam_to_base")
        # TODO 1: build the 4x4 transform T_base_camera: the rotation
        #         Rz(yaw) @ Ry(pitch) @ Rx(roll) in the top-left 3x3 block,
        #         the camera position in the last column.
        self.T_base_camera = np.eye(4)
        self.publisher = self.create_publisher(PointStamped, "pos_in_robot_base_frame", 10)
        self.subscription = self.create_subscription(
            PointStamped, "pos_in_cam_frame", self.on_point, 10
        )

    def on_point(self, msg):
        # TODO 2: p_base = T_base_camera @ (x, y, z, 1); publish its first three
        #         values with the input's stamp and frame_id "base_link".
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
