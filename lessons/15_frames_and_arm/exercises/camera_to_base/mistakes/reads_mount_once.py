"""Mistake: the mount read once at start-up; later parameter changes are ignored."""

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


class CamToBase(Node):
    def __init__(self):
        super().__init__("cam_to_base")
        for name, value in MOUNT.items():
            self.declare_parameter(name, value)
        self.T_base_camera = self.camera_transform()  # once, at start-up
        self.publisher = self.create_publisher(PointStamped, "pos_in_robot_base_frame", 10)
        self.subscription = self.create_subscription(
            PointStamped, "pos_in_cam_frame", self.on_point, 10
        )

    def camera_transform(self):
        """T_base_camera from the mount parameters as they are now."""
        m = {name: self.get_parameter(name).value for name in MOUNT}
        rotation = rot_z(m["camera_yaw"]) @ rot_y(m["camera_pitch"]) @ rot_x(m["camera_roll"])
        T_base_camera = np.eye(4)
        T_base_camera[:3, :3] = rotation
        T_base_camera[:3, 3] = [m["camera_x"], m["camera_y"], m["camera_z"]]
        return T_base_camera

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
