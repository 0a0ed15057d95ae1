"""Costmap2DROS: the costmap node a Nav2 server carries (``global_costmap``, ``local_costmap``).

As in Nav2, the planner server owns a node ``/global_costmap/global_costmap``
and the controller server one ``/local_costmap/local_costmap``; each runs in
its server's process and follows its server's lifecycle (``configure``,
``activate``...). The node

- subscribes to the map (``static_layer.map_topic``, ``/map``, transient
  local) and makes the costmap from it: static layer + inflation layer
  (:mod:`nav2_costmap_2d.costmap_2d`);
- publishes ``<name>/costmap`` (nav_msgs/OccupancyGrid, transient local,
  values as Nav2's costmap publisher translates them) whenever it changes;
- answers ``<name>/clear_entirely_<name>`` (nav2_msgs/ClearEntireCostmap:
  the costmap is rebuilt from the map) and ``<name>/get_costmap``
  (nav2_msgs/GetCostmap);
- knows where the robot is: ``get_robot_pose()`` reads
  ``global_frame -> robot_base_frame`` from TF.

Parameters (Nav2's names): ``global_frame`` (map), ``robot_base_frame``
(base_link), ``robot_radius`` (0.15 m: the diffbot's circumscribed radius is
0.14 m), ``track_unknown_space`` (true), ``transform_tolerance`` (0.3 s),
``static_layer.map_topic``, ``inflation_layer.inflation_radius`` (0.55 m),
``inflation_layer.cost_scaling_factor`` (3.0), ``inflation_layer.inflate_unknown``.
Not here: the obstacle and voxel layers (costs from ``/scan``), rolling
windows, footprint polygons.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np
from nav2_msgs.msg import Costmap as CostmapMsg
from nav2_msgs.srv import ClearEntireCostmap, GetCostmap
from nav_msgs.msg import OccupancyGrid
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.service import Service
from rclpy.subscription import Subscription
from rclpy.time import Time
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener

from nav2_costmap_2d.costmap_2d import Costmap2D, costmap_from_grid, to_occupancy_values

LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


def yaw_of(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class Costmap2DROS(Node):
    """One costmap, its topic and services, and the robot's pose from TF."""

    def __init__(self, name: str, parent_namespace: str = "", **kwargs: Any) -> None:
        namespace = (parent_namespace.rstrip("/") + "/" + name) if parent_namespace else name
        super().__init__(name, namespace=namespace, **kwargs)
        self.name = name
        p = self.declare_parameter
        p("global_frame", "map")
        p("robot_base_frame", "base_link")
        p("robot_radius", 0.15)
        p("track_unknown_space", True)
        p("transform_tolerance", 0.3)
        p("static_layer.map_topic", "/map")
        p("inflation_layer.inflation_radius", 0.55)
        p("inflation_layer.cost_scaling_factor", 3.0)
        p("inflation_layer.inflate_unknown", False)
        self.lock = threading.Lock()
        self.costmap: Costmap2D | None = None
        self.grid: OccupancyGrid | None = None
        self.costmap_msg: OccupancyGrid | None = None
        self.active = False
        self.tf_buffer = Buffer(node=self)
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.costmap_pub: Publisher | None = None
        self.map_sub: Subscription | None = None
        self.costmap_services: list[Service] = []

    # --- lifecycle, driven by the owning server ---
    def on_configure(self) -> None:
        self.global_frame = str(self.get_parameter("global_frame").value)
        self.robot_base_frame = str(self.get_parameter("robot_base_frame").value)
        self.transform_tolerance = float(self.get_parameter("transform_tolerance").value)
        self.costmap_pub = self.create_publisher(OccupancyGrid, "costmap", LATCHED)
        topic = str(self.get_parameter("static_layer.map_topic").value)
        self.map_sub = self.create_subscription(OccupancyGrid, topic, self.on_map, LATCHED)
        self.costmap_services = [
            self.create_service(
                ClearEntireCostmap, f"clear_entirely_{self.name}", self.on_clear_entirely
            ),
            self.create_service(GetCostmap, "get_costmap", self.on_get_costmap),
        ]
        self.get_logger().info(f"Subscribing to the map topic ({topic}) with transient local")

    def on_activate(self) -> None:
        self.active = True
        with self.lock:
            msg = self.costmap_msg
        if msg is not None and self.costmap_pub is not None:
            self.costmap_pub.publish(msg)

    def on_deactivate(self) -> None:
        self.active = False

    def on_cleanup(self) -> None:
        self.active = False
        if self.map_sub is not None:
            self.destroy_subscription(self.map_sub)
        if self.costmap_pub is not None:
            self.destroy_publisher(self.costmap_pub)
        for service in self.costmap_services:
            self.destroy_service(service)
        self.map_sub, self.costmap_pub, self.costmap_services = None, None, []
        with self.lock:
            self.costmap = self.grid = self.costmap_msg = None

    # --- the costmap ---
    def on_map(self, msg: OccupancyGrid) -> None:
        info = msg.info
        if info.width == 0 or info.height == 0 or not info.resolution > 0:
            self.get_logger().error("Received a map with no cells or a bad resolution: ignored")
            return
        self.get_logger().info(
            f"StaticLayer: Resizing costmap to {info.width} X {info.height} "
            f"at {info.resolution:g} m/pix"
        )
        with self.lock:
            self.grid = msg
        self.update_map()

    def update_map(self) -> None:
        """Rebuild the costmap from the newest map (static + inflation) and publish it."""
        with self.lock:
            msg = self.grid
        if msg is None:
            return
        info = msg.info
        data = np.asarray(msg.data, np.int8).reshape(info.height, info.width)
        g = self.get_parameter
        costmap = costmap_from_grid(
            data,
            info.resolution,
            (info.origin.position.x, info.origin.position.y),
            frame_id=msg.header.frame_id or "map",
            robot_radius=float(g("robot_radius").value),
            inflation_radius=float(g("inflation_layer.inflation_radius").value),
            cost_scaling_factor=float(g("inflation_layer.cost_scaling_factor").value),
            track_unknown_space=bool(g("track_unknown_space").value),
            inflate_unknown=bool(g("inflation_layer.inflate_unknown").value),
        )
        out = OccupancyGrid()
        out.header.frame_id = self.global_frame
        out.header.stamp = self.get_clock().now().to_msg()
        out.info = info
        out.data = to_occupancy_values(costmap.costs).ravel().tolist()
        with self.lock:
            self.costmap = costmap
            self.costmap_msg = out
        if self.active and self.costmap_pub is not None:
            self.costmap_pub.publish(out)

    def get_costmap(self) -> Costmap2D | None:
        with self.lock:
            return self.costmap

    def on_clear_entirely(self, request: Any, response: Any) -> Any:
        self.get_logger().info(f"Received request to clear entirely the {self.name}")
        self.update_map()
        return response

    def on_get_costmap(self, request: Any, response: Any) -> Any:
        costmap = self.get_costmap()
        msg = CostmapMsg()
        msg.header.frame_id = self.global_frame
        msg.header.stamp = self.get_clock().now().to_msg()
        if costmap is not None:
            meta = msg.metadata
            meta.update_time = msg.header.stamp
            meta.layer = "master"
            meta.resolution = float(costmap.resolution)
            meta.size_x, meta.size_y = costmap.size_x, costmap.size_y
            meta.origin.position.x, meta.origin.position.y = costmap.origin_x, costmap.origin_y
            meta.origin.orientation.w = 1.0
            msg.data = costmap.costs.ravel().tolist()
        response.map = msg
        return response

    # --- the robot ---
    def get_robot_pose(self) -> tuple[float, float, float] | None:
        """(x, y, yaw) of ``robot_base_frame`` in ``global_frame``, or None (logged)."""
        try:
            tf = self.tf_buffer.lookup_transform(
                self.global_frame,
                self.robot_base_frame,
                Time(),
                Duration(seconds=self.transform_tolerance),
            )
        except Exception as exc:  # tf2 raises its LookupException, ExtrapolationException...
            self.get_logger().error(f"Could not get robot pose: {exc}", throttle_duration_sec=2.0)
            return None
        t, q = tf.transform.translation, tf.transform.rotation
        return (t.x, t.y, yaw_of(q))

    def transform_pose(
        self, frame_id: str, x: float, y: float, yaw: float
    ) -> tuple[float, float, float] | None:
        """A pose given in ``frame_id`` into ``global_frame`` (None when TF cannot)."""
        if not frame_id or frame_id == self.global_frame:
            return (x, y, yaw)
        try:
            tf = self.tf_buffer.lookup_transform(
                self.global_frame, frame_id, Time(), Duration(seconds=self.transform_tolerance)
            )
        except Exception as exc:
            self.get_logger().error(f"Could not transform a pose from {frame_id}: {exc}")
            return None
        t, q = tf.transform.translation, tf.transform.rotation
        turn = yaw_of(q)
        c, s = math.cos(turn), math.sin(turn)
        return (t.x + c * x - s * y, t.y + s * x + c * y, yaw + turn)
