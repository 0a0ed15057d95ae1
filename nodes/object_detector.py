"""object_detector: find a coloured ball in camera images with plain OpenCV.

For every image on ``/camera/image_raw`` the node

1. converts BGR to HSV, where "red" is a hue range independent of brightness,
   and keeps the pixels inside the range (``cv2.inRange``; red wraps around
   hue 0, so two ranges are joined);
2. cleans the mask with a morphological opening (removes speckles);
3. takes the largest blob (``cv2.findContours``), its enclosing circle, and
   accepts it only if it is round enough (blob area / circle area);
4. turns the pixel circle into a 3D position with the pinhole model: a ball
   of known radius ``ball_radius`` metres that looks ``r`` pixels wide is
   ``Z = fx * ball_radius / r`` metres away, then ``X = (u - cx) Z / fx`` and
   ``Y = (v - cy) Z / fy`` (camera optical frame: x right, y down, z forward).

It publishes the annotated image on ``/object_detection/output``, a
``tutorial_interfaces/DetectedObject`` (label, pixel centre, radius, camera-
frame position) on ``/object_detection/object`` and, when ``publish_point``
is true, a ``PointStamped`` on ``/pos_in_cam_frame`` so that
``coordinate_transform`` and ``robotic_arm`` can reach for the ball.

No learned model is downloaded: colour and shape are enough for this scene.
Intrinsics (``fx``, ``fy``, ``cx``, ``cy``) default to a 525 px focal length
and the image centre.
"""

import math

import cv2
import numpy as np
from geometry_msgs.msg import PointStamped
from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image
from tutorial_interfaces.msg import DetectedObject

from nodes.common.image_conversion import array_to_image, image_to_bgr8
from nodes.common.run import spin_node

# Hue ranges in OpenCV's 0..179 scale, with minimum saturation and value.
COLOURS = {
    "red": [((0, 120, 70), (10, 255, 255)), ((170, 120, 70), (179, 255, 255))],
    "green": [((40, 80, 60), (85, 255, 255))],
    "blue": [((95, 120, 60), (130, 255, 255))],
}


def find_ball(bgr: np.ndarray, colour: str, min_radius: float, min_roundness: float):
    """(u, v, radius_px, mask) of the largest round blob of ``colour``, or None."""
    hsv = cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)
    mask = np.zeros(hsv.shape[:2], np.uint8)
    for low, high in COLOURS[colour]:
        mask |= cv2.inRange(hsv, np.array(low), np.array(high))
    mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, np.ones((5, 5), np.uint8))
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    if not contours:
        return None
    largest = max(contours, key=cv2.contourArea)
    (u, v), radius = cv2.minEnclosingCircle(largest)
    if radius < min_radius:
        return None
    roundness = cv2.contourArea(largest) / (math.pi * radius * radius)
    if roundness < min_roundness:
        return None
    return u, v, radius


def pixel_range(low: float, high: float, description: str) -> ParameterDescriptor:
    return ParameterDescriptor(
        description=f"{description}, pixels",
        floating_point_range=[FloatingPointRange(from_value=low, to_value=high)],
    )


def pixel_to_camera(u, v, radius_px, ball_radius, fx, fy, cx, cy):
    """Camera-frame centre (m) of a ball of known size seen at (u, v) with radius_px."""
    z = fx * ball_radius / radius_px
    return (u - cx) * z / fx, (v - cy) * z / fy, z


class ObjectDetector(Node):
    def __init__(self) -> None:
        super().__init__("object_detector")
        self.declare_parameter("colour", "red")  # a key of COLOURS, checked on set
        self.declare_parameter("ball_radius", 0.04)  # metres
        # Ranges: ROS refuses a zero or NaN divisor (pixel radius, focal length) with a reason.
        self.declare_parameter("min_radius", 6.0, pixel_range(1.0, 1000.0, "smallest ball radius"))
        self.declare_parameter("min_roundness", 0.6)
        self.declare_parameter("fx", 525.0, pixel_range(1.0, 100_000.0, "focal length along x"))
        self.declare_parameter("fy", 525.0, pixel_range(1.0, 100_000.0, "focal length along y"))
        self.declare_parameter("cx", -1.0)  # negative: the image centre
        self.declare_parameter("cy", -1.0)
        self.declare_parameter("publish_point", False)
        self.image_publisher = self.create_publisher(Image, "object_detection/output", 10)
        self.object_publisher = self.create_publisher(DetectedObject, "object_detection/object", 10)
        self.point_publisher = self.create_publisher(PointStamped, "pos_in_cam_frame", 10)
        self.subscription = self.create_subscription(
            Image, "camera/image_raw", self.on_image, qos_profile_sensor_data
        )
        self.add_on_set_parameters_callback(self.on_set_parameters)

    def on_set_parameters(self, params: list[Parameter]) -> SetParametersResult:
        for param in params:
            if param.name == "colour" and param.value not in COLOURS:
                return SetParametersResult(
                    successful=False,
                    reason=f"colour must be one of {', '.join(COLOURS)}; got {param.value!r:.40}",
                )
        return SetParametersResult(successful=True)

    def on_image(self, msg: Image) -> None:
        bgr = image_to_bgr8(msg, self.get_logger())
        if bgr is None:
            return  # an encoding we cannot read: skipped, with a warning
        colour = self.get_parameter("colour").value
        found = find_ball(
            bgr,
            colour,
            float(self.get_parameter("min_radius").value),
            float(self.get_parameter("min_roundness").value),
        )
        annotated = bgr.copy()
        if found is not None:
            u, v, radius = found
            cx = float(self.get_parameter("cx").value)
            cy = float(self.get_parameter("cy").value)
            cx = (msg.width - 1) / 2.0 if cx < 0 else cx
            cy = (msg.height - 1) / 2.0 if cy < 0 else cy
            x, y, z = pixel_to_camera(
                u,
                v,
                radius,
                float(self.get_parameter("ball_radius").value),
                float(self.get_parameter("fx").value),
                float(self.get_parameter("fy").value),
                cx,
                cy,
            )
            detection = DetectedObject()
            detection.header = msg.header
            detection.label = f"{colour}_ball"
            detection.pixel_x, detection.pixel_y, detection.radius_px = u, v, radius
            detection.position_in_camera.x = x
            detection.position_in_camera.y = y
            detection.position_in_camera.z = z
            self.object_publisher.publish(detection)
            if self.get_parameter("publish_point").value:
                point = PointStamped(header=msg.header)
                point.point.x, point.point.y, point.point.z = x, y, z
                self.point_publisher.publish(point)
            centre = (round(u), round(v))
            cv2.circle(annotated, centre, round(radius), (0, 255, 0), 2, cv2.LINE_AA)
            cv2.drawMarker(annotated, centre, (0, 255, 0), cv2.MARKER_CROSS, 14, 2)
            label = f"{colour} ball  ({x:+.2f}, {y:+.2f}, {z:.2f}) m"
            cv2.putText(
                annotated,
                label,
                (centre[0] - 80, max(20, centre[1] - round(radius) - 10)),
                cv2.FONT_HERSHEY_SIMPLEX,
                0.5,
                (0, 255, 0),
                1,
                cv2.LINE_AA,
            )
        else:
            cv2.putText(
                annotated, "no object", (10, 25), cv2.FONT_HERSHEY_SIMPLEX, 0.7, (0, 0, 255), 2
            )
        self.image_publisher.publish(array_to_image(annotated, "bgr8", header=msg.header))


def main(args=None) -> None:
    spin_node(ObjectDetector, args)


if __name__ == "__main__":
    main()
