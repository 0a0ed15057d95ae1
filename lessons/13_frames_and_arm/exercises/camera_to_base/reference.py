"""Reference solution: re-express camera-frame points in the robot's base frame."""

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
        rotation = rot_z(CAMERA_YAW) @ rot_y(CAMERA_PITCH) @ rot_x(CAMERA_ROLL)
        self.T_base_camera = np.eye(4)
        self.T_base_camera[:3, :3] = rotation
        self.T_base_camera[:3, 3] = [CAMERA_X, CAMERA_Y, CAMERA_Z]
        self.publisher = self.create_publisher(PointStamped, "pos_in_robot_base_frame", 10)
        self.subscription = self.create_subscription(
            PointStamped, "pos_in_cam_frame", self.on_point, 10
        )

    def on_point(self, msg):
        p_camera = np.array([msg.point.x, msg.point.y, msg.point.z, 1.0])
        p_base = self.T_base_camera @ p_camera
        out = PointStamped()
        out.header.stamp = msg.header.stamp  # the same moment, seen from another frame
        out.header.frame_id = "base_link"
        out.point.x, out.point.y, out.point.z = (float(v) for v in p_base[:3])
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
