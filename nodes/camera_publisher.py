"""camera_publisher: pretend a camera sees an object and publish where it is.

A real pick-and-place cell would run an object detector on the camera images
(see ``object_detector``). Here the "camera" invents the object's position so
the rest of the chain can be studied on its own: every ``period`` seconds the
object jumps to a new random spot on the table, and its position is
published on ``/pos_in_cam_frame`` at ``rate`` Hz.

ROS concepts shown
- ``geometry_msgs/PointStamped``: a point plus a header; ``header.frame_id``
  ("camera") says in which coordinate frame the numbers are written and
  ``header.stamp`` says when the camera saw them;
- parameters (``period``, ``rate``, ``seed``, ``depth``) declared with defaults
  and overridable with ``--ros-args -p name:=value``.

The camera frame is the optical frame: x to the right of the image, y down,
z straight out of the lens (the depth). The default camera pose in
``coordinate_transform`` looks straight down at the table from 0.7 m, so the
object sits about 0.62 m in front of the lens.

Try it: ``ros2 run tutorial_nodes camera_publisher`` then echo ``/pos_in_cam_frame``.
"""

import numpy as np
from geometry_msgs.msg import PointStamped
from rclpy.node import Node

from nodes.common.run import spin_node


class CameraPublisher(Node):
    def __init__(self) -> None:
        super().__init__("camera_publisher")
        self.declare_parameter("rate", 5.0)  # Hz
        self.declare_parameter("period", 4.0)  # seconds before the object moves
        self.declare_parameter("seed", 0)
        self.declare_parameter("depth", 0.62)  # metres from the lens to the object
        self.rng = np.random.default_rng(self.get_parameter("seed").value)
        self.publisher = self.create_publisher(PointStamped, "pos_in_cam_frame", 10)
        rate = float(self.get_parameter("rate").value)
        self.ticks_per_move = max(1, round(float(self.get_parameter("period").value) * rate))
        self.tick = 0
        self.position = self.new_position()
        self.timer = self.create_timer(1.0 / rate, self.on_timer)

    def new_position(self) -> tuple[float, float, float]:
        # A spot in the middle of the image; x and y in metres at the object's depth.
        x, y = self.rng.uniform(-0.15, 0.15, 2)
        depth = float(self.get_parameter("depth").value) + self.rng.uniform(-0.02, 0.02)
        return float(x), float(y), depth

    def on_timer(self) -> None:
        if self.tick and self.tick % self.ticks_per_move == 0:
            self.position = self.new_position()
            x, y, z = self.position
            self.get_logger().info(f"object moved to ({x:.3f}, {y:.3f}, {z:.3f}) m (camera frame)")
        self.tick += 1
        msg = PointStamped()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = "camera"
        msg.point.x, msg.point.y, msg.point.z = self.position
        self.publisher.publish(msg)


def main(args=None) -> None:
    spin_node(CameraPublisher, args)


if __name__ == "__main__":
    main()
