"""image_publisher: publish camera images as sensor_msgs/Image (bgr8).

Where the pictures come from, in order of preference:

1. ``video_path``: a video file read with OpenCV (looped when ``loop`` is true);
2. ``camera_index`` >= 0: a webcam (``/dev/video<N>``);
3. otherwise a synthetic scene drawn with OpenCV: a wooden-looking table, a
   blue box and a green triangle that stay put, and a red ball that wanders
   around. It works on any machine, with no camera attached.

Frames go out on ``/camera/image_raw`` at ``fps`` frames per second.

ROS concepts shown
- ``sensor_msgs/Image``: height, width, ``encoding`` (how to read a pixel),
  ``step`` (bytes per row) and the raw bytes. Without cv_bridge we fill those
  fields ourselves (``nodes/common/image_conversion.py``);
- sensor QoS (``qos_profile_sensor_data``: best effort, keep a few): for a
  camera a fresh frame matters more than a lost old one.
"""

import math

import cv2
import numpy as np
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image

from nodes.common.image_conversion import array_to_image
from nodes.common.run import spin_node
from nodes.common.video_capture import read_frame

BALL_RADIUS_PX = 34  # a 4 cm ball, 0.62 m from a 525 px focal-length camera


class SyntheticScene:
    """A table seen from above with a red ball moving on a Lissajous curve."""

    def __init__(self, width: int, height: int) -> None:
        self.width, self.height = width, height
        rng = np.random.default_rng(3)
        grain = rng.normal(0, 10, (height, 1)) + np.linspace(0, 25, height)[:, None]
        base = np.array([70, 120, 160], np.float32)  # BGR, a light wood tone
        table = base + grain[..., None] + rng.normal(0, 4, (height, width, 1))
        self.background = np.clip(table, 0, 255).astype(np.uint8)
        cv2.rectangle(self.background, (40, 40), (130, 120), (200, 90, 20), -1)
        triangle = np.array([[width - 60, 60], [width - 140, 150], [width - 30, 160]])
        cv2.fillPoly(self.background, [triangle.astype(np.int32)], (40, 170, 40), cv2.LINE_AA)

    def ball_centre(self, t: float) -> tuple[float, float]:
        u = self.width / 2 + 0.35 * self.width * math.sin(0.5 * t)
        v = self.height / 2 + 0.30 * self.height * math.sin(0.7 * t + 0.6)
        return u, v

    def render(self, t: float) -> np.ndarray:
        frame = self.background.copy()
        u, v = self.ball_centre(t)
        centre = (round(u), round(v))
        cv2.circle(frame, (centre[0] + 6, centre[1] + 8), BALL_RADIUS_PX, (40, 60, 80), -1)
        cv2.circle(frame, centre, BALL_RADIUS_PX, (30, 30, 210), -1, cv2.LINE_AA)
        cv2.circle(frame, (centre[0] - 10, centre[1] - 10), 8, (140, 140, 255), -1, cv2.LINE_AA)
        return frame


class ImagePublisher(Node):
    def __init__(self) -> None:
        super().__init__("image_publisher")
        self.declare_parameter("video_path", "")
        self.declare_parameter("camera_index", -1)
        self.declare_parameter("loop", True)
        self.declare_parameter("fps", 15.0)
        self.declare_parameter("width", 640)
        self.declare_parameter("height", 480)
        self.declare_parameter("frame_id", "camera")
        self.width = int(self.get_parameter("width").value)
        self.height = int(self.get_parameter("height").value)
        self.capture = self.open_capture()
        self.scene = None if self.capture else SyntheticScene(self.width, self.height)
        self.publisher = self.create_publisher(Image, "camera/image_raw", qos_profile_sensor_data)
        self.frames = 0
        # Read once: the timer's period and the synthetic scene's clock must agree.
        self.fps = float(self.get_parameter("fps").value)
        self.timer = self.create_timer(1.0 / self.fps, self.on_timer)

    def open_capture(self) -> cv2.VideoCapture | None:
        path = self.get_parameter("video_path").value
        index = int(self.get_parameter("camera_index").value)
        if not path and index < 0:
            self.get_logger().info("no video_path or camera_index: drawing a synthetic scene")
            return None
        capture = cv2.VideoCapture(path if path else index)
        if not capture.isOpened():
            self.get_logger().error(
                f"cannot open {path or f'camera {index}'}; using the synthetic scene"
            )
            return None
        self.get_logger().info(f"reading frames from {path or f'camera {index}'}")
        return capture

    def next_frame(self) -> np.ndarray | None:
        if self.capture is None:
            assert self.scene is not None  # no capture: the synthetic scene exists
            return self.scene.render(self.frames / self.fps)
        loop = bool(self.get_parameter("loop").value)
        return read_frame(self.capture, loop, self.width, self.height)

    def on_timer(self) -> None:
        frame = self.next_frame()
        if frame is None:
            self.get_logger().info("end of the video", once=True)
            return
        msg = array_to_image(frame, "bgr8")
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = self.get_parameter("frame_id").value
        self.publisher.publish(msg)
        self.frames += 1

    def destroy_node(self) -> None:
        if self.capture is not None:
            self.capture.release()
        super().destroy_node()


def main(args=None) -> None:
    spin_node(ImagePublisher, args)


if __name__ == "__main__":
    main()
