"""Exercise: a mask of the red pixels of every camera image."""

import cv2
import numpy as np
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image


def image_to_bgr(msg):
    """A bgr8 Image as an (H, W, 3) uint8 array. Rows may end with padding: use step."""
    rows = np.frombuffer(msg.data, dtype=np.uint8).reshape(msg.height, msg.step)
    return np.ascontiguousarray(rows[:, : msg.width * 3]).reshape(msg.height, msg.width, 3)


def array_to_image(array, encoding, header):
    """An (H, W) or (H, W, C) uint8 array as an Image with the given encoding and header."""
    channels = 1 if array.ndim == 2 else array.shape[2]
    msg = Image(header=header, height=array.shape[0], width=array.shape[1], encoding=encoding)
    msg.step = array.shape[1] * channels
    msg.data = np.ascontiguousarray(array, dtype=np.uint8).tobytes()
    return msg


class Masker(Node):
    def __init__(self):
        super().__init__("masker")
        self.subscription = self.create_subscription(
            Image, "camera/image_raw", self.on_image, qos_profile_sensor_data
        )
        self.publisher = self.create_publisher(Image, "camera/red_mask", 10)

    def on_image(self, msg):
        if msg.encoding != "bgr8":
            self.get_logger().warning(f"expected bgr8, got {msg.encoding}", once=True)
            return
        bgr = image_to_bgr(msg)
        # TODO 1: convert bgr to HSV and keep the red pixels: hue 0-10 or
        #         170-179, saturation and value at least 100. cv2.inRange gives
        #         255 inside a range and 0 outside; join two masks with |.
        mask = np.zeros(bgr.shape[:2], dtype=np.uint8)
        # TODO 2: publish the mask on camera/red_mask: array_to_image(mask, ...)
        #         with the encoding "mono8" and the input's header.
        self.get_logger().info(f"a {mask.shape[1]}x{mask.shape[0]} mask, not sent yet", once=True)


def main():
    rclpy.init()
    node = Masker()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
