"""Costmap2DROS: the costmap node a Nav2 server carries (``global_costmap``, ``local_costmap``).

As in Nav2, the planner server owns a node ``/global_costmap/global_costmap``
and the controller server one ``/local_costmap/local_costmap``; each runs in
its server's process and follows its server's lifecycle (``configure``,
``activate``...). The node

- subscribes to the map (``static_layer.map_topic``, ``/map``, transient
  local): the static layer;
- subscribes to each of ``obstacle_layer.observation_sources`` (LaserScans,
  ``/scan``): the obstacle layer marks what the scans hit and clears, by
  raytracing, what they see through (:mod:`nav2_costmap_2d.obstacle_layer`);
- ``update_frequency`` times a second puts the obstacle layer over the static
  one and inflates the result (:mod:`nav2_costmap_2d.costmap_2d`): the costmap
  the planner and the controller read;
- publishes ``<name>/costmap`` (nav_msgs/OccupancyGrid, transient local,
  values as Nav2's costmap publisher translates them) at
  ``publish_frequency`` when it changed;
- answers ``<name>/clear_entirely_<name>`` (nav2_msgs/ClearEntireCostmap:
  the obstacle layer forgets what it saw) and ``<name>/get_costmap``
  (nav2_msgs/GetCostmap);
- knows where the robot is: ``get_robot_pose()`` reads
  ``global_frame -> robot_base_frame`` from TF.

Parameters (Nav2's names): ``global_frame`` (map), ``robot_base_frame``
(base_link), ``robot_radius`` (0.15 m: the diffbot's circumscribed radius is
0.14 m), ``track_unknown_space`` (true), ``transform_tolerance`` (0.3 s),
``update_frequency`` and ``publish_frequency`` (the server passes Nav2's
configured values: global 1 and 1 Hz, local 5 and 2 Hz), ``plugins``
(``[static_layer, obstacle_layer, inflation_layer]``; leave
``obstacle_layer`` out for a map-only costmap), ``static_layer.map_topic``,
``<layer>.plugin`` (Nav2's class of each layer, logged at configure),
``obstacle_layer.enabled``, ``obstacle_layer.observation_sources`` (``scan``),
``obstacle_layer.footprint_clearing_enabled`` (true), and per source
``obstacle_layer.<source>.topic`` (``/<source>``), ``.marking``,
``.clearing`` (true), ``.obstacle_max_range`` (2.5 m),
``.obstacle_min_range`` (0), ``.raytrace_max_range`` (3.0 m),
``.raytrace_min_range`` (0), ``.inf_is_valid`` (false),
``inflation_layer.inflation_radius`` (0.55 m),
``inflation_layer.cost_scaling_factor`` (3.0), ``inflation_layer.inflate_unknown``.
Where Nav2's code defaults would leave a layer idle (no observation source,
``clearing`` false) these are the values of Nav2's shipped
``nav2_params.yaml``; nav2_bringup's ``params/nav2_params.yaml`` holds them all.
Not here: voxel layers, point clouds, rolling windows (the local costmap
covers the whole map), footprint polygons, layer plugins of one's own.
"""

from __future__ import annotations

import array
import functools
import math
import threading
import uuid
from typing import Any

import numpy as np
from nav2_msgs.msg import Costmap as CostmapMsg
from nav2_msgs.srv import ClearEntireCostmap, GetCostmap
from nav_msgs.msg import OccupancyGrid
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from rclpy.service import Service
from rclpy.subscription import Subscription
from rclpy.time import Time
from rclpy.timer import Timer
from sensor_msgs.msg import LaserScan
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener

from nav2_costmap_2d.costmap_2d import Costmap2D, inflate, static_layer, to_occupancy_values
from nav2_costmap_2d.obstacle_layer import (
    ObservationSource,
    ObstacleLayer,
    observation_from_scan,
)

LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
# The layers here, with the class Nav2's params files name for each (``<layer>.plugin``).
LAYER_PLUGINS = {
    "static_layer": "nav2_costmap_2d::StaticLayer",
    "obstacle_layer": "nav2_costmap_2d::ObstacleLayer",
    "inflation_layer": "nav2_costmap_2d::InflationLayer",
}
SCAN_MAX_AGE = 1.0  # s: a scan whose transform is still missing after this is dropped


def own_listener(buffer: Buffer) -> TransformListener:
    """A TransformListener on a node and thread of its own, as Nav2's C++ servers make one.

    Its node ignores the process's command line (as rclcpp's does,
    ``use_global_arguments(false)``): a launch file's ``-r __node:=bt_navigator``
    would otherwise rename it too, and two nodes of one name answer each other's
    parameter services.
    """
    node = Node(
        f"transform_listener_impl_{uuid.uuid4().hex[:12]}",
        use_global_arguments=False,
        start_parameter_services=False,
    )
    return TransformListener(buffer, node, spin_thread=True)


def stop_listener(listener: TransformListener) -> None:
    """End a TransformListener that spins a node of its own: its thread, then its node."""
    executor = getattr(listener, "executor", None)
    if executor is not None:
        executor.shutdown(timeout_sec=1.0)
    thread = getattr(listener, "dedicated_listener_thread", None)
    if thread is not None:
        thread.join(timeout=2.0)
    listener.node.destroy_node()


def yaw_of(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class Costmap2DROS(Node):
    """One costmap, its layers, topic and services, and the robot's pose from TF."""

    def __init__(
        self,
        name: str,
        parent_namespace: str = "",
        defaults: dict[str, Any] | None = None,
        **kwargs: Any,
    ) -> None:
        namespace = (parent_namespace.rstrip("/") + "/" + name) if parent_namespace else name
        # As Nav2's: its own name and namespace before the process's remaps (a launch file's
        # `-r __node:=planner_server` is for the server), the params file's values still apply.
        absolute = namespace if namespace.startswith("/") else "/" + namespace
        own = ["--ros-args", "-r", f"__node:={name}", "-r", f"__ns:={absolute}"]
        kwargs["cli_args"] = [*own, *(kwargs.get("cli_args") or [])]
        super().__init__(name, namespace=namespace, **kwargs)
        self.name = name
        given = {"update_frequency": 5.0, "publish_frequency": 1.0, **(defaults or {})}
        p = self.declare_parameter
        p("global_frame", "map")
        p("robot_base_frame", "base_link")
        p("robot_radius", 0.15)
        p("track_unknown_space", True)
        p("transform_tolerance", 0.3)
        p("update_frequency", float(given["update_frequency"]))
        p("publish_frequency", float(given["publish_frequency"]))
        p("plugins", ["static_layer", "obstacle_layer", "inflation_layer"])
        for layer, plugin in LAYER_PLUGINS.items():
            p(f"{layer}.plugin", plugin)
        p("static_layer.map_topic", "/map")
        p("obstacle_layer.enabled", True)
        p("obstacle_layer.observation_sources", "scan")
        p("obstacle_layer.footprint_clearing_enabled", True)
        p("inflation_layer.inflation_radius", 0.55)
        p("inflation_layer.cost_scaling_factor", 3.0)
        p("inflation_layer.inflate_unknown", False)
        self.lock = threading.Lock()
        self.costmap: Costmap2D | None = None
        self.grid: OccupancyGrid | None = None
        self.costmap_msg: OccupancyGrid | None = None
        self.static_costs: np.ndarray | None = None  # the static layer of the newest map
        self.obstacles: ObstacleLayer | None = None
        self.sources: list[ObservationSource] = []
        self.scans: dict[str, tuple[LaserScan, float]] = {}  # source -> newest scan, when
        self.changed = False  # the costmap changed since it was last published
        self.active = False
        self.tf_buffer = Buffer(node=self)
        # As Nav2's C++ listener: a node and a thread of its own (transform_listener_impl_*).
        # /tf comes at 60-80 messages a wall second with the world at twice real time; each
        # one through this node's multi-threaded executor cost a wake-up of its whole wait
        # set (about a third of the process's CPU), through a one-node executor very little.
        self.tf_listener = own_listener(self.tf_buffer)
        self.fixed_frame: str | None = None  # odom: see lookup_now
        self.own_executor: SingleThreadedExecutor | None = None
        self.own_thread: threading.Thread | None = None
        self.costmap_pub: Publisher | None = None
        self.map_sub: Subscription | None = None
        self.scan_subs: list[Subscription] = []
        self.costmap_services: list[Service] = []
        self.cycle_timers: list[Timer] = []

    # --- lifecycle, driven by the owning server ---
    def on_configure(self) -> None:
        self.spin_in_own_thread()
        g = self.get_parameter
        self.global_frame = str(g("global_frame").value)
        self.robot_base_frame = str(g("robot_base_frame").value)
        self.transform_tolerance = float(g("transform_tolerance").value)
        self.costmap_pub = self.create_publisher(OccupancyGrid, "costmap", LATCHED)
        topic = str(g("static_layer.map_topic").value)
        self.map_sub = self.create_subscription(OccupancyGrid, topic, self.on_map, LATCHED)
        self.costmap_services = [
            self.create_service(
                ClearEntireCostmap, f"clear_entirely_{self.name}", self.on_clear_entirely
            ),
            self.create_service(GetCostmap, "get_costmap", self.on_get_costmap),
        ]
        self.get_logger().info(f"Subscribing to the map topic ({topic}) with transient local")
        for layer in [str(v) for v in g("plugins").value or []]:
            if layer not in LAYER_PLUGINS:
                self.get_logger().warning(f'No layer "{layer}" here: it is left out')
                continue
            self.get_logger().info(f'Using plugin "{layer}" ({g(f"{layer}.plugin").value})')
        self.sources = self.configure_sources()

    def configure_sources(self) -> list[ObservationSource]:
        """The obstacle layer's LaserScan sources and their subscriptions (none if not a plugin)."""
        plugins = [str(v) for v in self.get_parameter("plugins").value or []]
        if "obstacle_layer" not in plugins:
            return []
        if not bool(self.get_parameter("obstacle_layer.enabled").value):
            return []
        names = str(self.get_parameter("obstacle_layer.observation_sources").value).split()
        sources = []
        for source in names:
            defaults = ObservationSource(name=source, topic=f"/{source}")
            values: dict[str, Any] = {}
            for field in ("topic", "marking", "clearing", "inf_is_valid"):
                values[field] = self._source_parameter(source, field, getattr(defaults, field))
            for field in (
                "obstacle_max_range",
                "obstacle_min_range",
                "raytrace_max_range",
                "raytrace_min_range",
            ):
                values[field] = float(
                    self._source_parameter(source, field, getattr(defaults, field))
                )
            data_type = str(self._source_parameter(source, "data_type", "LaserScan"))
            if data_type != "LaserScan":
                self.get_logger().error(
                    f"Only LaserScan observation sources are supported here: {source} is "
                    f"{data_type}, left out"
                )
                continue
            sources.append(ObservationSource(name=source, **values))
            self.scan_subs.append(
                self.create_subscription(
                    LaserScan,
                    str(values["topic"]),
                    functools.partial(self.on_scan, source),
                    qos_profile_sensor_data,
                )
            )
        if sources:
            self.get_logger().info(
                "Subscribed to Topics: " + " ".join(str(src.topic) for src in sources)
            )
        return sources

    def _source_parameter(self, source: str, field: str, default: Any) -> Any:
        name = f"obstacle_layer.{source}.{field}"
        if not self.has_parameter(name):
            self.declare_parameter(name, default)
        return self.get_parameter(name).value

    def on_activate(self) -> None:
        self.active = True
        with self.lock:
            msg = self.costmap_msg
            self.changed = False
        if msg is not None and self.costmap_pub is not None:
            self.costmap_pub.publish(msg)
        for name, callback in (
            ("update_frequency", self.update_costmap),
            ("publish_frequency", self.publish_costmap),
        ):
            rate = float(self.get_parameter(name).value)
            if rate > 0:
                self.cycle_timers.append(self.create_timer(1.0 / rate, callback))

    def on_deactivate(self) -> None:
        self.active = False
        for timer in self.cycle_timers:
            self.destroy_timer(timer)
        self.cycle_timers = []

    def on_cleanup(self) -> None:
        self.on_deactivate()
        if self.map_sub is not None:
            self.destroy_subscription(self.map_sub)
        for sub in self.scan_subs:
            self.destroy_subscription(sub)
        if self.costmap_pub is not None:
            self.destroy_publisher(self.costmap_pub)
        for service in self.costmap_services:
            self.destroy_service(service)
        self.map_sub, self.costmap_pub, self.costmap_services = None, None, []
        self.scan_subs, self.sources = [], []
        with self.lock:
            self.costmap = self.grid = self.costmap_msg = None
            self.static_costs = self.obstacles = None
            self.scans = {}

    # --- the layers ---
    def on_map(self, msg: OccupancyGrid) -> None:
        info = msg.info
        if info.width == 0 or info.height == 0 or not info.resolution > 0:
            self.get_logger().error("Received a map with no cells or a bad resolution: ignored")
            return
        self.get_logger().info(
            f"StaticLayer: Resizing costmap to {info.width} X {info.height} "
            f"at {info.resolution:g} m/pix"
        )
        data = np.asarray(msg.data, np.int8).reshape(info.height, info.width)
        unknown = bool(self.get_parameter("track_unknown_space").value)
        costs = static_layer(data, track_unknown_space=unknown)
        origin = (info.origin.position.x, info.origin.position.y)
        with self.lock:
            self.grid = msg
            self.static_costs = costs
            self.obstacles = ObstacleLayer(
                costs.shape, info.resolution, origin, track_unknown_space=unknown
            )
        self.update_map()

    def on_scan(self, source: str, msg: LaserScan) -> None:
        with self.lock:  # only the newest scan of each source: Nav2's observation_persistence 0
            self.scans[source] = (msg, self.get_clock().now().nanoseconds * 1e-9)

    def take_observations(self) -> list[Any]:
        """The newest scans whose sensor pose TF knows, in the costmap's frame."""
        with self.lock:
            pending = dict(self.scans)
        now = self.get_clock().now().nanoseconds * 1e-9
        observations = []
        for source in self.sources:
            found = pending.get(source.name)
            if found is None:
                continue
            msg, received = found
            try:
                tf = self.lookup_now(msg.header.frame_id, Time.from_msg(msg.header.stamp))
            except Exception as exc:  # its odometry not on /tf yet: try again next update
                if now - received > SCAN_MAX_AGE:
                    self.get_logger().warning(
                        f"Dropped a {source.name} observation: no transform from "
                        f"{msg.header.frame_id} to {self.global_frame} ({exc})",
                        throttle_duration_sec=5.0,
                    )
                    self._forget(source.name, msg)
                continue
            self._forget(source.name, msg)
            t, q = tf.transform.translation, tf.transform.rotation
            observations.append(
                observation_from_scan(
                    np.asarray(msg.ranges, np.float64),
                    msg.angle_min,
                    msg.angle_increment,
                    msg.range_min,
                    msg.range_max,
                    (t.x, t.y, yaw_of(q)),
                    source,
                )
            )
        return observations

    def _forget(self, source: str, msg: LaserScan) -> None:
        with self.lock:
            if source in self.scans and self.scans[source][0] is msg:
                del self.scans[source]

    def update_costmap(self) -> None:
        """One update cycle: the newest observations into the obstacle layer, then the costmap."""
        if self.obstacles is None or not self.sources:
            return
        observations = self.take_observations()
        footprint = bool(self.get_parameter("obstacle_layer.footprint_clearing_enabled").value)
        if not observations and not footprint:
            return
        layer = self.obstacles
        before = layer.grid.copy()
        layer.update(observations)
        if footprint:
            pose = self.get_robot_pose(quiet=True)
            if pose is not None:
                radius = float(self.get_parameter("robot_radius").value)
                layer.clear_footprint(pose[0], pose[1], radius)
        if not np.array_equal(before, layer.grid):
            self.update_map(publish=False)

    def update_map(self, publish: bool = True) -> None:
        """The costmap from the static layer, the obstacle layer and inflation."""
        with self.lock:
            msg, static, layer = self.grid, self.static_costs, self.obstacles
        if msg is None or static is None:
            return
        info = msg.info
        g = self.get_parameter
        master = layer.update_with_max(static) if layer is not None and self.sources else static
        costs = inflate(
            master,
            info.resolution,
            inflation_radius=float(g("inflation_layer.inflation_radius").value),
            cost_scaling_factor=float(g("inflation_layer.cost_scaling_factor").value),
            inscribed_radius=float(g("robot_radius").value),
            inflate_unknown=bool(g("inflation_layer.inflate_unknown").value),
        )
        costmap = Costmap2D(
            costs,
            float(info.resolution),
            float(info.origin.position.x),
            float(info.origin.position.y),
            msg.header.frame_id or "map",
        )
        out = OccupancyGrid()
        out.header.frame_id = self.global_frame
        out.header.stamp = self.get_clock().now().to_msg()
        out.info = info
        # Bytes, not a list of 40,000 ints: rclpy takes an array.array as it is.
        out.data = array.array("b", to_occupancy_values(costs).tobytes())
        with self.lock:
            self.costmap = costmap
            self.costmap_msg = out
            self.changed = not publish
        if publish and self.active and self.costmap_pub is not None:
            self.costmap_pub.publish(out)

    def publish_costmap(self) -> None:
        with self.lock:
            msg = self.costmap_msg if self.changed else None
            self.changed = False
        if msg is not None and self.active and self.costmap_pub is not None:
            self.costmap_pub.publish(msg)

    def get_costmap(self) -> Costmap2D | None:
        with self.lock:
            return self.costmap

    def on_clear_entirely(self, request: Any, response: Any) -> Any:
        self.get_logger().info(f"Received request to clear entirely the {self.name}")
        with self.lock:
            layer = self.obstacles
        if layer is not None:
            layer.reset()
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

    def spin_in_own_thread(self) -> None:
        """As Nav2's Costmap2DROS: this node's callbacks on an executor and thread of its own.

        The server's multi-threaded executor costs a few milliseconds of Python for every
        wake-up; /scan alone wakes it 20 times a wall second with the world at twice real time,
        each time taking the interpreter from the planning or the control loop. A one-node
        single-threaded executor handles a message for a fraction of that.
        """
        if self.own_executor is not None:
            return
        executor = SingleThreadedExecutor()
        executor.add_node(self)  # and out of the server's executor: a node has one at a time
        thread = threading.Thread(target=self._spin, args=(executor,), daemon=True)
        self.own_executor, self.own_thread = executor, thread
        thread.start()

    def _spin(self, executor: SingleThreadedExecutor) -> None:
        try:
            executor.spin()
        except Exception:  # the context shut down under it: the process is ending
            pass

    def destroy_node(self) -> None:
        if self.own_executor is not None:
            self.own_executor.shutdown(timeout_sec=1.0)
            if self.own_thread is not None:
                self.own_thread.join(timeout=2.0)
        stop_listener(self.tf_listener)
        super().destroy_node()

    # --- the robot ---
    def odom_frame(self) -> str | None:
        """The parent of ``robot_base_frame`` (odom) when it is not ``global_frame`` itself."""
        if self.fixed_frame is None:
            mark = f"Frame {self.robot_base_frame} exists with parent "
            for line in self.tf_buffer.all_frames_as_string().splitlines():
                if line.startswith(mark):
                    self.fixed_frame = line[len(mark) :].rstrip(".")
        if self.fixed_frame in (None, self.global_frame, self.robot_base_frame):
            return None
        return self.fixed_frame

    def lookup_now(self, source_frame: str, stamp: Time, timeout: float = 0.0) -> Any:
        """``source_frame`` at ``stamp`` in ``global_frame``, with amcl's newest correction.

        Ours (Nav2 looks up ``global_frame`` at ``stamp``): amcl dates map -> odom
        ``transform_tolerance`` (1 s) ahead, so a lookup at a time interpolates the
        correction amcl sent that long before. After a quick turn on the spot (this robot's
        odometry over-counts turns by a few per cent) that put the pose and the scans'
        obstacles a few degrees off. Here odom -> ``source_frame`` is taken at ``stamp``
        and the correction as it is now.
        """
        wait = Duration(seconds=timeout)
        odom = self.odom_frame()
        if odom is None:
            return self.tf_buffer.lookup_transform(self.global_frame, source_frame, stamp, wait)
        return self.tf_buffer.lookup_transform_full(
            self.global_frame, Time(), source_frame, stamp, odom, wait
        )

    def get_robot_pose(self, quiet: bool = False) -> tuple[float, float, float] | None:
        """(x, y, yaw) of ``robot_base_frame`` in ``global_frame``, or None (logged)."""
        try:
            tf = self.lookup_now(
                self.robot_base_frame, Time(), 0.0 if quiet else self.transform_tolerance
            )
        except Exception as exc:  # tf2 raises its LookupException, ExtrapolationException...
            if not quiet:
                self.get_logger().error(
                    f"Could not get robot pose: {exc}", throttle_duration_sec=2.0
                )
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
