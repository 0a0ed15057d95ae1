"""Accepted, written differently: the transform cached and rebuilt when a parameter changes
(a post-set callback), the rotation built from a quaternion."""

import math

import numpy as np
import rclpy
from geometry_msgs.msg import PointStamped
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

DEFAULTS = {"x": 0.30, "y": -0.20, "z": 0.65, "roll": -2.6, "pitch": 0.1, "yaw": 0.5}


def rotation_from_rpy(roll, pitch, yaw):
    """Fixed-axis roll, pitch, yaw as a rotation matrix, through a quaternion."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    w = cr * cp * cy + sr * sp * sy
    x = sr * cp * cy - cr * sp * sy
    y = cr * sp * cy + sr * cp * sy
    z = cr * cp * sy - sr * sp * cy
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


class CamToBase(Node):
    def __init__(self):
        super().__init__("cam_to_base")
        for key, value in DEFAULTS.items():
            self.declare_parameter("camera_" + key, value)
        self.rebuild()
        self.add_post_set_parameters_callback(lambda _params: self.rebuild())
        self.out = self.create_publisher(PointStamped, "/pos_in_robot_base_frame", 10)
        self.create_subscription(PointStamped, "/pos_in_cam_frame", self.on_point, 10)

    def rebuild(self):
        m = {k: self.get_parameter("camera_" + k).value for k in DEFAULTS}
        self.rotation = rotation_from_rpy(m["roll"], m["pitch"], m["yaw"])
        self.offset = np.array([m["x"], m["y"], m["z"]])

    def on_point(self, msg):
        p = self.rotation @ np.array([msg.point.x, msg.point.y, msg.point.z]) + self.offset
        out = PointStamped()
        out.header.stamp = msg.header.stamp
        out.header.frame_id = "base_link"
        out.point.x, out.point.y, out.point.z = (float(v) for v in p)
        self.out.publish(out)


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
