"""Mistake: publishes the red parts of the picture, not a mask."""

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
        hsv = cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)
        # Red sits at both ends of the hue circle (0..179 in OpenCV).
        low = cv2.inRange(hsv, (0, 100, 100), (10, 255, 255))
        high = cv2.inRange(hsv, (170, 100, 100), (179, 255, 255))
        mask = cv2.bitwise_or(low, high)  # 255 where red, 0 elsewhere
        red_parts = cv2.bitwise_and(bgr, bgr, mask=mask)
        self.publisher.publish(array_to_image(red_parts, "bgr8", msg.header))


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
