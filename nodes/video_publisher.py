"""video_publisher: the SLAM lesson's camera (``vod_img_pub`` in the original tutorial).

Publishes frames on ``/cam/image_raw`` (``sensor_msgs/Image``, bgr8) at
``fps`` frames per second. With ``video_path`` set it plays that file
(looping when ``loop`` is true). By default it renders a synthetic sequence:
a camera flying a closed loop inside a textured room
(``nodes/common/synthetic_world.py``). Because that trajectory is known, the
node also publishes the true camera pose on ``/cam/ground_truth_pose``
(``geometry_msgs/PoseStamped`` in the ``world`` frame): compare it with what
``slam_node`` estimates.

The synthetic camera has a focal length of 0.82 x image width pixels and its
principal point in the image centre; ``slam_node`` assumes the same by default.
"""

import cv2
import numpy as np
from geometry_msgs.msg import PoseStamped
from rclpy.node import Node
from sensor_msgs.msg import Image

from nodes.common.frames import matrix_to_quaternion
from nodes.common.image_conversion import array_to_image
from nodes.common.run import spin_node
from nodes.common.synthetic_world import SyntheticSequence
from nodes.common.video_capture import read_frame


class VideoPublisher(Node):
    def __init__(self) -> None:
        super().__init__("video_publisher")
        self.declare_parameter("video_path", "")
        self.declare_parameter("loop", True)
        self.declare_parameter("fps", 10.0)
        self.declare_parameter("width", 640)
        self.declare_parameter("height", 480)
        self.declare_parameter("frames_per_loop", 300)  # synthetic: frames for one lap
        self.width = int(self.get_parameter("width").value)
        self.height = int(self.get_parameter("height").value)
        self.capture: cv2.VideoCapture | None = None
        self.sequence: SyntheticSequence | None = None
        path = self.get_parameter("video_path").value
        if path:
            self.capture = cv2.VideoCapture(path)
            if not self.capture.isOpened():
                self.get_logger().error(f"cannot open {path}; rendering the synthetic room instead")
                self.capture = None
        if self.capture is None:
            self.sequence = SyntheticSequence(
                int(self.get_parameter("frames_per_loop").value), self.width, self.height
            )
            self.get_logger().info("rendering the synthetic room sequence")
        self.image_publisher = self.create_publisher(Image, "cam/image_raw", 10)
        self.truth_publisher = self.create_publisher(PoseStamped, "cam/ground_truth_pose", 10)
        self.index = 0
        self.timer = self.create_timer(1.0 / float(self.get_parameter("fps").value), self.on_timer)

    def on_timer(self) -> None:
        stamp = self.get_clock().now().to_msg()
        frame: np.ndarray | None
        if self.sequence is not None:
            frame = self.sequence.frame(self.index)
            pose = self.sequence.pose(self.index)
            truth = PoseStamped()
            truth.header.stamp = stamp
            truth.header.frame_id = "world"
            p = truth.pose.position
            p.x, p.y, p.z = (float(v) for v in pose[:3, 3])
            o = truth.pose.orientation
            o.x, o.y, o.z, o.w = matrix_to_quaternion(pose[:3, :3])
            self.truth_publisher.publish(truth)
        else:
            assert self.capture is not None  # no synthetic sequence: a video file is open
            loop = bool(self.get_parameter("loop").value)
            frame = read_frame(self.capture, loop, self.width, self.height)
            if frame is None:
                self.get_logger().info("end of the video", once=True)
                return
        msg = array_to_image(frame, "bgr8")
        msg.header.stamp = stamp
        msg.header.frame_id = "camera"
        self.image_publisher.publish(msg)
        self.index += 1

    def destroy_node(self) -> None:
        if self.capture is not None:
            self.capture.release()
        super().destroy_node()


def main(args=None) -> None:
    spin_node(VideoPublisher, args)


if __name__ == "__main__":
    main()
