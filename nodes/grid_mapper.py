"""grid_mapper: builds an occupancy grid map from /scan while the robot drives.

Mapping with known poses, as the textbooks start it: every scan is laid into
a grid of log-odds at the pose the scanner had when it took it
(``nodes/common/occupancy_grid.py`` has the update and Bresenham's beams).
What it publishes is what a SLAM node (slam_toolbox, gmapping) publishes, so
map_saver_cli, the 3D view and later AMCL read it the same way:

- ``/map`` (nav_msgs/OccupancyGrid, reliable + transient local as map_server
  publishes it: a late subscriber still gets the newest map), every
  ``map_update_interval`` seconds while it changes: -1 unknown, 0 free,
  100 occupied, 5 cm cells (``resolution``); the grid grows as the robot
  sees further (``initial_size``, ``grow_margin``, ``max_size``, metres);
- ``/map_metadata`` (nav_msgs/MapMetaData, latched the same way);
- ``map -> odom`` on ``/tf``: where the odometry's frame sits in the map.

Where the poses come from (``pose_source``):

- ``ground_truth`` (the default, for the simulated world): the simulator
  knows where the robot is (``/ground_truth/odom``, frame ``world``), so the
  map frame is the world frame (published as ``map -> world``, identity, on
  ``/tf_static``) and ``map -> odom`` is exactly the odometry's error. Start
  sim_world with ``publish_world_tf:=false`` so that odom has this one parent;
- ``odom``: dead reckoning only, ``map -> odom`` is the identity. The wheels'
  error then bends the walls as the robot drives: what SLAM is there to fix.

The scanner's pose at each scan's stamp is looked up through tf2:
``map -> odom`` (ours) ``-> base_link`` (the base's odometry on /tf) ``->
lidar_link`` (robot_state_publisher's /tf_static). A scan that arrives before
its transforms waits a moment; one whose frames never appear is reported.

Parameters are read at start (read-only afterwards) except
``map_update_interval``. A value that cannot work stops the node at start with
the reason.

Try it: ``ros2 run sim_world sim_world --ros-args -p world:=office -p
publish_world_tf:=false``, robot_state_publisher, this node, then drive.
"""

from __future__ import annotations

import array
import math
from collections import deque
from typing import Any

from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import MapMetaData, OccupancyGrid, Odometry
from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.time import Time
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage
from tf2_ros import (
    Buffer,
    ConnectivityException,
    ExtrapolationException,
    LookupException,
    StaticTransformBroadcaster,
    TransformBroadcaster,
    TransformListener,
)

from nodes.common.occupancy_grid import LogOddsGrid, LogOddsModel, scan_endpoints
from nodes.common.run import spin_node

POSE_SOURCES = ("ground_truth", "odom")
PENDING_SCANS = 20  # scans waiting for their transforms, at most
WAIT_FOR_TF_SEC = 1.0  # of stamps: a scan older than the newest pose by this much is dropped
PAIRING_SEC = 2.0  # odometry and ground truth kept this long to pair them by stamp
LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
SCANS = QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)  # hears reliable ones too


def _range(low: float, high: float, text: str, read_only: bool = True) -> ParameterDescriptor:
    return ParameterDescriptor(
        description=text,
        read_only=read_only,
        floating_point_range=[FloatingPointRange(from_value=low, to_value=high)],
    )


def _nanoseconds(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def _planar(msg: Odometry) -> tuple[float, float, float, float, float, float, float]:
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    return (p.x, p.y, p.z, q.x, q.y, q.z, q.w)


def _yaw(x: float, y: float, z: float, w: float) -> float:
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def map_to_odom(truth: tuple[float, ...], odom: tuple[float, ...]) -> tuple[float, float, float]:
    """(x, y, yaw) of the odom frame in the map, so that map -> odom -> base_link is the truth."""
    tx, ty, _tz, *tq = truth
    ox, oy, _oz, *oq = odom
    yaw = _yaw(*tq) - _yaw(*oq)
    c, s = math.cos(yaw), math.sin(yaw)
    return tx - (c * ox - s * oy), ty - (s * ox + c * oy), math.atan2(math.sin(yaw), math.cos(yaw))


class GridMapper(Node):
    def __init__(self) -> None:
        super().__init__("grid_mapper")
        p = self.declare_parameter
        p("resolution", 0.05, _range(0.01, 1.0, "m per cell"))
        p("initial_size", 10.0, _range(1.0, 200.0, "m: the square the map starts with"))
        p("grow_margin", 2.0, _range(0.0, 50.0, "m added beyond what the map must cover"))
        p("max_size", 60.0, _range(2.0, 500.0, "m: the map never grows past this square"))
        p("log_odds_hit", 0.85, _range(0.01, 10.0, "added where a beam ends (p 0.7)"))
        p("log_odds_miss", -0.4, _range(-10.0, -0.01, "added where a beam passes (p 0.4)"))
        p("log_odds_min", -2.0, _range(-50.0, -0.01, "clamp (p 0.12)"))
        p("log_odds_max", 3.5, _range(0.01, 50.0, "clamp (p 0.97)"))
        p("occupied_thresh", 0.65, _range(0.0, 1.0, "probability above which a cell is 100"))
        p("free_thresh", 0.25, _range(0.0, 1.0, "probability below which a cell is 0"))
        p(
            "map_update_interval",
            1.0,
            _range(0.1, 60.0, "s between two /map messages while the map changes", False),
        )
        text = ParameterDescriptor
        p(
            "pose_source",
            "ground_truth",
            text(description="ground_truth or odom", read_only=True),
        )
        for name, value in (
            ("map_frame", "map"),
            ("odom_frame", "odom"),
            ("base_frame", "base_link"),
            ("world_frame", "world"),
        ):
            p(name, value, text(description="TF frame name", read_only=True))
        g = self._param
        self.pose_source = str(g("pose_source"))
        if self.pose_source not in POSE_SOURCES:
            raise ValueError(f"pose_source must be one of {', '.join(POSE_SOURCES)}")
        self.map_frame, self.odom_frame = str(g("map_frame")), str(g("odom_frame"))
        self.base_frame, self.world_frame = str(g("base_frame")), str(g("world_frame"))
        model = LogOddsModel(
            hit=float(g("log_odds_hit")),
            miss=float(g("log_odds_miss")),
            minimum=float(g("log_odds_min")),
            maximum=float(g("log_odds_max")),
            occupied_thresh=float(g("occupied_thresh")),
            free_thresh=float(g("free_thresh")),
        )
        problem = model.check()
        if problem:
            raise ValueError(problem)
        self.model = model
        self.grid: LogOddsGrid | None = None  # made at the first scan, around the robot
        self.published_updates = -1
        self.map_stamp = Time().to_msg()
        self.pending: deque[LaserScan] = deque()
        self.dropped = 0
        self.odom_poses: dict[int, tuple[float, ...]] = {}
        self.truth_poses: dict[int, tuple[float, ...]] = {}
        self.newest_pose_ns = 0
        self.warned_parent = False

        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.tf_broadcaster = TransformBroadcaster(self)
        self.static_broadcaster = StaticTransformBroadcaster(self)
        self.map_pub = self.create_publisher(OccupancyGrid, "map", LATCHED)
        self.metadata_pub = self.create_publisher(MapMetaData, "map_metadata", LATCHED)
        self.create_subscription(LaserScan, "scan", self.on_scan, SCANS)
        self.create_subscription(Odometry, "odom", self.on_odom, 20)
        if self.pose_source == "ground_truth":
            self.create_subscription(Odometry, "ground_truth/odom", self.on_ground_truth, 20)
            if self.world_frame:
                self.static_broadcaster.sendTransform(
                    self.identity(self.map_frame, self.world_frame)
                )
        self.create_subscription(TFMessage, "/tf", self.on_tf, 10)
        self.map_timer = self.create_timer(float(g("map_update_interval")), self.on_map_timer)
        self.add_on_set_parameters_callback(self.on_parameters)
        where = (
            f"ground truth (/ground_truth/odom): {self.map_frame} is the {self.world_frame} frame"
            if self.pose_source == "ground_truth"
            else "odometry alone: map -> odom stays the identity, drift goes into the map"
        )
        self.get_logger().info(
            f"mapping /scan into {float(g('resolution')):g} m cells; poses from {where}"
        )

    def _param(self, name: str) -> Any:
        return self.get_parameter(name).value

    def identity(self, parent: str, child: str) -> TransformStamped:
        t = TransformStamped()
        t.header.stamp = self.get_clock().now().to_msg()
        t.header.frame_id, t.child_frame_id = parent, child
        t.transform.rotation.w = 1.0
        return t

    # --- poses: map -> odom ------------------------------------------------------------
    def on_odom(self, msg: Odometry) -> None:
        stamp = _nanoseconds(msg.header.stamp)
        if self.pose_source == "odom":
            self.publish_map_to_odom(msg.header.stamp, (0.0, 0.0, 0.0))
            return
        pose = _planar(msg)
        truth = self.truth_poses.pop(stamp, None)
        if truth is None:
            self._keep(self.odom_poses, stamp, pose)
        else:
            self.publish_map_to_odom(msg.header.stamp, map_to_odom(truth, pose))

    def on_ground_truth(self, msg: Odometry) -> None:
        stamp = _nanoseconds(msg.header.stamp)
        pose = _planar(msg)
        odom = self.odom_poses.pop(stamp, None)
        if odom is None:
            self._keep(self.truth_poses, stamp, pose)
        else:
            self.publish_map_to_odom(msg.header.stamp, map_to_odom(pose, odom))

    def _keep(self, poses: dict[int, tuple[float, ...]], stamp: int, pose: tuple[float, ...]):
        poses[stamp] = pose
        oldest = stamp - int(PAIRING_SEC * 1e9)
        for old in [s for s in poses if s < oldest]:
            del poses[old]
        if len(poses) > 1000:  # stamps that never pair (a simulation reset): start afresh
            poses.clear()

    def publish_map_to_odom(self, stamp: Any, pose: tuple[float, float, float]) -> None:
        x, y, yaw = pose
        t = TransformStamped()
        t.header.stamp = stamp
        t.header.frame_id, t.child_frame_id = self.map_frame, self.odom_frame
        t.transform.translation.x, t.transform.translation.y = x, y
        t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        self.tf_buffer.set_transform(t, self.get_name())
        self.tf_broadcaster.sendTransform(t)
        stamp_ns = _nanoseconds(stamp)
        if stamp_ns < self.newest_pose_ns - int(PAIRING_SEC * 1e9):  # time went back: a reset
            self.pending.clear()
        self.newest_pose_ns = stamp_ns
        self.process_pending()

    def on_tf(self, msg: TFMessage) -> None:
        """Say once if someone else gives odom a parent: TF must stay a tree."""
        if self.warned_parent:
            return
        for t in msg.transforms:
            parent = t.header.frame_id.lstrip("/")
            if t.child_frame_id.lstrip("/") == self.odom_frame and parent != self.map_frame:
                self.warned_parent = True
                self.get_logger().warning(
                    f"{self.odom_frame} also has the parent '{parent}' on /tf: a frame may have "
                    f"one parent only. With sim_world, start it with publish_world_tf:=false"
                )

    # --- scans ---------------------------------------------------------------------------
    def on_scan(self, msg: LaserScan) -> None:
        self.pending.append(msg)
        while len(self.pending) > PENDING_SCANS:
            self.pending.popleft()
            self.dropped += 1
            source = (
                "/ground_truth/odom and /odom" if self.pose_source == "ground_truth" else "/odom"
            )
            self.get_logger().warning(
                f"scans wait for a pose that does not come: is {source} published?",
                throttle_duration_sec=5.0,
            )
        self.process_pending()

    def process_pending(self) -> None:
        while self.pending:
            scan = self.pending[0]
            try:
                t = self.tf_buffer.lookup_transform(
                    self.map_frame, scan.header.frame_id, Time.from_msg(scan.header.stamp)
                )
            except ExtrapolationException as exc:
                age = self.newest_pose_ns - _nanoseconds(scan.header.stamp)
                if age < WAIT_FOR_TF_SEC * 1e9:
                    return  # its pose has not arrived yet: wait
                self.pending.popleft()
                self.dropped += 1
                self.get_logger().warning(
                    f"dropped a scan: no pose at its stamp ({exc})", throttle_duration_sec=5.0
                )
                continue
            except (LookupException, ConnectivityException) as exc:
                self.pending.popleft()
                self.dropped += 1
                self.get_logger().warning(
                    f"waiting for {self.map_frame} -> {scan.header.frame_id or '(no frame)'} "
                    f"on TF ({exc}); is robot_state_publisher running?",
                    throttle_duration_sec=5.0,
                )
                continue
            self.pending.popleft()
            self.integrate(scan, t)

    def integrate(self, scan: LaserScan, t: TransformStamped) -> None:
        q, p = t.transform.rotation, t.transform.translation
        sensor = (p.x, p.y, _yaw(q.x, q.y, q.z, q.w))
        if self.grid is None:
            self.grid = LogOddsGrid(
                float(self._param("resolution")),
                self.model,
                center=(p.x, p.y),
                initial_size=float(self._param("initial_size")),
                margin=float(self._param("grow_margin")),
                max_size=float(self._param("max_size")),
            )
        ends, hit = scan_endpoints(
            scan.ranges,
            scan.angle_min,
            scan.angle_increment,
            scan.range_min,
            scan.range_max,
            sensor,
        )
        self.grid.integrate((p.x, p.y), ends, hit)
        self.map_stamp = scan.header.stamp

    # --- the map -------------------------------------------------------------------------
    def on_map_timer(self) -> None:
        grid = self.grid
        if grid is None or grid.updates == self.published_updates:
            return
        self.published_updates = grid.updates
        info = MapMetaData()
        info.map_load_time = self.map_stamp
        info.resolution = float(grid.resolution)
        info.width, info.height = grid.width, grid.height
        info.origin.position.x, info.origin.position.y = grid.origin
        info.origin.orientation.w = 1.0
        msg = OccupancyGrid(info=info)
        msg.header.stamp = self.map_stamp
        msg.header.frame_id = self.map_frame
        msg.data = array.array("b", grid.occupancy().tobytes())
        self.map_pub.publish(msg)
        self.metadata_pub.publish(info)

    def on_parameters(self, params: list[Parameter]) -> SetParametersResult:
        for param in params:
            if param.name == "map_update_interval":
                period = float(param.value)
                self.map_timer.cancel()
                self.destroy_timer(self.map_timer)
                self.map_timer = self.create_timer(period, self.on_map_timer)
                self.get_logger().info(f"map_update_interval set to {period:g} s")
        return SetParametersResult(successful=True)


def main(args: list[str] | None = None) -> None:
    spin_node(GridMapper, args, program="grid_mapper")


if __name__ == "__main__":
    main()
