"""slam_node: monocular visual odometry and mapping (``slam_pub`` in the original tutorial).

It subscribes to ``/cam/image_raw`` and runs, frame by frame, the pipeline in
``nodes/common/slam.py``: track corners with optical flow, initialise from
the essential matrix (``cv2.findEssentialMat`` + ``cv2.recoverPose``),
locate each new frame against the 3D map (PnP), triangulate new map points.

Published:

- ``/cam/map_points`` (``sensor_msgs/PointCloud2``: x, y, z float32 and an
  rgb colour sampled from the image) every ``map_period`` seconds;
- ``/cam/camera_pose`` (``visualization_msgs/MarkerArray``): the trajectory
  as a line strip plus an arrow for the current camera;
- ``/cam/feature_ext_viz`` (``sensor_msgs/Image``): the frame with the tracked
  features drawn, green when they have a 3D point, yellow while waiting.

Frames: SLAM's own world is the first camera's optical frame (z forward, y
down); everything is published in ``map``, the same space turned so that z
is up and x is the first camera's viewing direction. A single camera cannot
measure scale: one map unit is the distance moved before initialisation.

Intrinsics ``fx``, ``fy``, ``cx``, ``cy`` (pixels); zero means "like the
synthetic camera" (focal 0.82 x width, centre of the image).
"""

import time

import cv2
import numpy as np
from geometry_msgs.msg import Point
from rclpy.node import Node
from sensor_msgs.msg import Image, PointCloud2
from visualization_msgs.msg import Marker, MarkerArray

from nodes.common.frames import BODY_FROM_OPTICAL, make_transform, matrix_to_quaternion
from nodes.common.image_conversion import array_to_image, image_to_bgr8
from nodes.common.pointcloud import xyz_to_pointcloud2
from nodes.common.run import spin_node
from nodes.common.slam import FrameResult, MonocularVO

# map frame (z up) from SLAM world (first camera, optical axes)
T_MAP_WORLD = make_transform(BODY_FROM_OPTICAL)


def draw_features(bgr: np.ndarray, result: FrameResult) -> np.ndarray:
    canvas = bgr.copy()
    for (x, y), mapped in zip(result.tracked, result.mapped, strict=True):
        colour = (0, 255, 0) if mapped else (0, 220, 255)
        cv2.circle(canvas, (int(x), int(y)), 3, colour, 1, cv2.LINE_AA)
    text = f"{result.state}  tracks {len(result.tracked)}  map {result.map_size}"
    cv2.putText(canvas, text, (10, 22), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (255, 255, 255), 2)
    return canvas


class SlamNode(Node):
    def __init__(self) -> None:
        super().__init__("slam_node")
        for name in ("fx", "fy", "cx", "cy"):
            self.declare_parameter(name, 0.0)
        self.declare_parameter("map_period", 0.5)  # seconds between map clouds
        self.declare_parameter("max_published_points", 50000)
        self.vo: MonocularVO | None = None
        self.trajectory: list[np.ndarray] = []
        self.last_map_time = 0.0
        self.processing_time = 0.0
        self.frames = 0
        self.map_publisher = self.create_publisher(PointCloud2, "cam/map_points", 10)
        self.pose_publisher = self.create_publisher(MarkerArray, "cam/camera_pose", 10)
        self.feature_publisher = self.create_publisher(Image, "cam/feature_ext_viz", 10)
        # Keep only the newest frame waiting: a slow machine skips frames, never lags.
        self.subscription = self.create_subscription(Image, "cam/image_raw", self.on_image, 1)

    def make_vo(self, width: int, height: int) -> MonocularVO:
        fx = float(self.get_parameter("fx").value) or 0.82 * width
        fy = float(self.get_parameter("fy").value) or fx
        cx = float(self.get_parameter("cx").value) or (width - 1) / 2.0
        cy = float(self.get_parameter("cy").value) or (height - 1) / 2.0
        K = np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])
        self.get_logger().info(f"intrinsics fx={fx:.1f} fy={fy:.1f} cx={cx:.1f} cy={cy:.1f}")
        return MonocularVO(K)

    def on_image(self, msg: Image) -> None:
        bgr = image_to_bgr8(msg, self.get_logger())
        if bgr is None:
            return  # an encoding we cannot read: skipped, with a warning
        if self.vo is None:
            self.vo = self.make_vo(msg.width, msg.height)
        start = time.perf_counter()
        result = self.vo.process(bgr)
        self.processing_time += time.perf_counter() - start
        self.frames += 1
        if result.state in ("initialised", "lost"):
            self.get_logger().info(f"frame {result.index}: {result.state}")
        if result.pose is not None:
            self.trajectory.append((T_MAP_WORLD @ result.pose)[:3, 3].copy())
        self.feature_publisher.publish(
            array_to_image(draw_features(bgr, result), "bgr8", header=msg.header)
        )
        self.publish_markers(result, msg)
        now = time.monotonic()
        if now - self.last_map_time >= float(self.get_parameter("map_period").value):
            self.last_map_time = now
            self.publish_map(self.vo, msg)
        if self.frames % 100 == 0:
            fps = self.frames / max(self.processing_time, 1e-9)
            self.get_logger().info(f"{self.frames} frames, {fps:.1f} frames/s of SLAM work")

    def publish_map(self, vo: MonocularVO, msg: Image) -> None:
        points, colours = vo.points, vo.colors
        limit = int(self.get_parameter("max_published_points").value)
        if len(points) > limit:  # the newest points: where the camera is now
            points, colours = points[-limit:], colours[-limit:]
        in_map = points @ T_MAP_WORLD[:3, :3].T
        cloud = xyz_to_pointcloud2(in_map, colours, frame_id="map", stamp=msg.header.stamp)
        self.map_publisher.publish(cloud)

    def publish_markers(self, result: FrameResult, msg: Image) -> None:
        markers = MarkerArray()
        path = Marker()
        path.header.frame_id = "map"
        path.header.stamp = msg.header.stamp
        path.ns, path.id = "trajectory", 0
        path.type, path.action = Marker.LINE_STRIP, Marker.ADD
        path.scale.x = 0.02
        path.color.r, path.color.g, path.color.b, path.color.a = 1.0, 0.5, 0.0, 1.0
        path.pose.orientation.w = 1.0
        path.points = [Point(x=float(p[0]), y=float(p[1]), z=float(p[2])) for p in self.trajectory]
        markers.markers.append(path)
        if result.pose is not None:
            pose = T_MAP_WORLD @ result.pose
            arrow = Marker()
            arrow.header = path.header
            arrow.ns, arrow.id = "camera", 1
            arrow.type, arrow.action = Marker.ARROW, Marker.ADD
            arrow.scale.x, arrow.scale.y, arrow.scale.z = 0.3, 0.05, 0.05
            arrow.color.g, arrow.color.b, arrow.color.a = 0.8, 1.0, 1.0
            arrow.pose.position.x, arrow.pose.position.y, arrow.pose.position.z = (
                float(v) for v in pose[:3, 3]
            )
            # An arrow marker points along its x axis; the camera looks along its z axis.
            look = pose[:3, :3] @ BODY_FROM_OPTICAL.T
            q = matrix_to_quaternion(look)
            o = arrow.pose.orientation
            o.x, o.y, o.z, o.w = q
            markers.markers.append(arrow)
        self.pose_publisher.publish(markers)


def main(args=None) -> None:
    spin_node(SlamNode, args)


if __name__ == "__main__":
    main()
