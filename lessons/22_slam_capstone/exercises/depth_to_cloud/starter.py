"""Exercise: turn depth images into point clouds (a pinhole camera in reverse)."""

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
    # TODO 1: describe one point and pack them all:
    #         - fields: three PointField (name "x", "y", "z"; offset 0, 4, 8;
    #           datatype PointField.FLOAT32; count 1);
    #         - point_step (bytes per point), row_step (bytes per row),
    #           is_bigendian False, is_dense True;
    #         - data: the points as little-endian float32 bytes.
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
        # TODO 2: one point per pixel that has a reading (depth > 0 and not NaN):
        #         z = depth, x = (u - CX) * z / FX, y = (v - CY) * z / FY, where
        #         u is the pixel's column and v its row. np.indices and a
        #         boolean mask do it without a Python loop.
        points = np.zeros((0, 3), dtype=np.float32)
        self.get_logger().info(f"a {depth.shape[1]}x{depth.shape[0]} depth image", once=True)
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
