"""Mistake: rows and columns mixed up (u taken as the row)."""

import numpy as np
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import Image, PointCloud2, PointField

# The depth camera's intrinsics, in pixels (from its calibration).
FX, FY = 150.0, 150.0
CX, CY = 79.5, 59.5


def depth_to_array(msg):
    """A 32FC1 Image (metres) as an (H, W) float32 array. Rows may be padded: use step."""
    rows = np.frombuffer(msg.data, dtype=np.uint8).reshape(msg.height, msg.step)
    pixels = np.ascontiguousarray(rows[:, : msg.width * 4])
    dtype = ">f4" if msg.is_bigendian else "<f4"
    return pixels.view(dtype).reshape(msg.height, msg.width).astype(np.float32)


def make_cloud(points, header):
    """An unordered PointCloud2 (height 1) with float32 fields x, y, z."""
    cloud = PointCloud2(header=header, height=1, width=len(points))
    cloud.fields = [
        PointField(name=name, offset=4 * i, datatype=PointField.FLOAT32, count=1)
        for i, name in enumerate("xyz")
    ]
    cloud.is_bigendian = False
    cloud.point_step = 12  # three float32
    cloud.row_step = cloud.point_step * cloud.width
    cloud.is_dense = True  # no NaN inside: invalid pixels were left out
    cloud.data = np.ascontiguousarray(points, dtype="<f4").tobytes()
    return cloud


class DepthCloud(Node):
    def __init__(self):
        super().__init__("depth_cloud")
        self.subscription = self.create_subscription(Image, "depth/image_raw", self.on_depth, 10)
        self.publisher = self.create_publisher(PointCloud2, "depth/points", 10)

    def on_depth(self, msg):
        if msg.encoding != "32FC1":
            self.get_logger().warning(f"expected 32FC1, got {msg.encoding}", once=True)
            return
        depth = depth_to_array(msg)
        u, v = np.indices(depth.shape)
        valid = np.isfinite(depth) & (depth > 0)  # 0 and NaN: no reading
        z = depth[valid]
        x = (u[valid] - CY) * z / FY
        y = (v[valid] - CX) * z / FX
        points = np.stack([x, y, z], axis=1)
        self.publisher.publish(make_cloud(points, msg.header))


def main():
    rclpy.init()
    node = DepthCloud()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
