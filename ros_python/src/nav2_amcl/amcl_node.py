"""amcl: Nav2's localization server, a lifecycle node as in Nav2 Jazzy.

``ros2 run nav2_amcl amcl`` starts it *unconfigured*; ``configure`` reads the
parameters (a value that cannot work makes configure fail with the reason in
the log) and makes its topics and services, ``activate`` starts localizing.

- in: ``map`` (nav_msgs/OccupancyGrid, transient local), ``scan``
  (sensor_msgs/LaserScan), ``initialpose``
  (geometry_msgs/PoseWithCovarianceStamped, frame ``global_frame_id``), the
  robot's odometry as ``odom_frame_id -> base_frame_id`` on /tf;
- out: ``amcl_pose`` (PoseWithCovarianceStamped, transient local),
  ``particle_cloud`` (nav2_msgs/ParticleCloud, best effort) and
  ``global_frame_id -> odom_frame_id`` on /tf (``tf_broadcast``);
- services: ``reinitialize_global_localization`` (std_srvs/Empty: particles
  over all free space), ``request_nomotion_update`` (std_srvs/Empty: the next
  scan updates the filter without motion), ``set_initial_pose``
  (nav2_msgs/SetInitialPose).

As in Nav2: nothing is published until an initial pose is known (from
``initialpose``, ``set_initial_pose``, the ``set_initial_pose`` parameter or
a global reinitialisation); the filter updates when the odometry moved more
than ``update_min_d`` along x or y or turned more than ``update_min_a``;
between updates the last ``map -> odom`` is sent again with each scan,
stamped ``transform_tolerance`` ahead; a map that comes after the first one
replaces what the scans are weighed against and leaves the particles where
they are. Bad input is refused with a warning
and the node runs on: an initial pose in another frame, with NaNs or off the
map, a map with no cells.

Differences, said plainly: ``base_frame_id`` defaults to ``base_link`` (the
course's diffbot has no ``base_footprint``; Nav2's default is
``base_footprint``); the laser model defaults to ``likelihood_field_prob``
with ``do_beamskip`` (``beam_skip_distance`` 0.2 m) and the filter updates
every 0.1 m / 0.1 rad (``COURSE_DEFAULTS``; Nav2: ``likelihood_field``, no
skipping, 0.5 m, 0.25 m / 0.2 rad); a spread filter weighs with the sum of
cubes whichever model is chosen (``ParticleFilter.update_gathered``);
``reinitialize_global_localization`` publishes the spread particles at once;
``beam`` is not implemented (refused at configure); parameters are read at
configure (no dynamic reconfigure).
"""

from __future__ import annotations

import math
import sys
import time
from typing import Any

import numpy as np
import rclpy
from geometry_msgs.msg import PoseWithCovarianceStamped, TransformStamped
from lifecycle_msgs.msg import State
from nav2_msgs.msg import ParticleCloud
from nav2_msgs.srv import SetInitialPose
from nav2_util.lifecycle_node import LifecycleNode
from nav_msgs.msg import OccupancyGrid
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException
from rclpy.lifecycle import LifecycleState, TransitionCallbackReturn
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
)
from rclpy.time import Time
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty
from tf2_ros import Buffer, TransformBroadcaster, TransformListener

from nav2_amcl.cloud import particle_cloud_cdr
from nav2_amcl.map import FREE, AmclMap
from nav2_amcl.motion_model import angle_diff
from nav2_amcl.particle_filter import FilterParameters, ParticleFilter
from nav2_amcl.sensor_model import ScanBeams

LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
CLOUD_QOS = QoSProfile(
    depth=5, reliability=ReliabilityPolicy.BEST_EFFORT, history=HistoryPolicy.KEEP_LAST
)
DEFAULT_COV = (0.5 * 0.5, 0.5 * 0.5, (math.pi / 12.0) ** 2)  # x, y, yaw of a parameter pose
PENDING_SCAN_AGE = 0.5  # s a scan may wait for its odometry on /tf before it is dropped

# Nav2 Jazzy's amcl parameters and defaults (the filter's own are in FilterParameters).
NODE_DEFAULTS: dict[str, Any] = {
    "base_frame_id": "base_link",  # Nav2: base_footprint; the course's diffbot has base_link
    "global_frame_id": "map",
    "odom_frame_id": "odom",
    "scan_topic": "scan",
    "map_topic": "map",
    "transform_tolerance": 1.0,
    "update_min_a": 0.2,
    "update_min_d": 0.25,
    "tf_broadcast": True,
    "set_initial_pose": False,
    "always_reset_initial_pose": False,
    "first_map_only": False,
    "initial_pose.x": 0.0,
    "initial_pose.y": 0.0,
    "initial_pose.z": 0.0,
    "initial_pose.yaw": 0.0,
    "save_pose_rate": 0.5,
    "lambda_short": 0.1,
    "random_seed": -1,  # ours: >= 0 makes the filter repeatable (tests, graders)
}


# Where this node's defaults differ from Nav2's, for the course's diffbot in the office.
# Measured by replaying recorded office tours (bench/nav_localization.py --record) through
# the filter: with Nav2's sum-of-cubes likelihood_field the estimate wandered (p95 0.20-0.25 m,
# 7-8 degrees; tuned, still 0.05-0.11 m and 4-6 degrees), with the product of the beams
# (likelihood_field_prob) it keeps within 0.03-0.06 m and a degree, once the particles have
# gathered (see ParticleFilter.update_gathered). The product is thrown by what the map lacks
# (a box on the floor): beam skipping leaves such beams out, but only with a skip distance
# under Nav2's 0.5 m, since in a 1.5 m corridor almost any end point lies within 0.5 m of a
# wall. Updating every 0.1 m / 0.1 rad lets the scans correct a turn's drift sooner (this
# robot's odometry over-counts turns by a few per cent).
COURSE_DEFAULTS: dict[str, Any] = {
    "laser_model_type": "likelihood_field_prob",
    "do_beamskip": True,
    "beam_skip_distance": 0.2,
    "update_min_d": 0.1,
    "update_min_a": 0.1,
}


def yaw_of(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def compose(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple:
    """a (+) b: b given in a's frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2])


def inverse(a: tuple[float, float, float]) -> tuple[float, float, float]:
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], -a[2])


def pose2d(t: TransformStamped) -> tuple[float, float, float]:
    tr = t.transform
    return (tr.translation.x, tr.translation.y, yaw_of(tr.rotation))


class AmclNode(LifecycleNode):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__("amcl", **kwargs)
        self.get_logger().info("Creating")
        defaults = {**vars(FilterParameters()), **NODE_DEFAULTS, **COURSE_DEFAULTS}
        for name, value in defaults.items():
            self.declare_parameter(name, value)
        self.active = False
        self.pf: ParticleFilter | None = None
        self.amcl_map: AmclMap | None = None
        self.map_frame = "map"
        self.params = FilterParameters()
        self.first_map_received = False
        self.initial_pose_known = False
        self.pending_initial_pose: PoseWithCovarianceStamped | None = None
        self.init_pose = (0.0, 0.0, 0.0)
        self.init_cov = np.diag(DEFAULT_COV)
        self.pf_init = False  # the odometry pose of the last update is known
        self.pf_odom_pose = (0.0, 0.0, 0.0)
        self.force_update = False
        self.latest_tf: tuple[float, float, float] | None = None  # map -> odom
        self.laser_poses: dict[str, tuple[float, float, float]] = {}
        self.pending_scan: LaserScan | None = None
        self.pending_since = 0.0  # time.monotonic() when the pending scan came
        self.last_update_ms = 0.0
        self._made: list[Any] = []
        self.tf_buffer: Buffer | None = None
        self.tf_listener: TransformListener | None = None
        self.tf_broadcaster: TransformBroadcaster | None = None
        self.pose_pub: Any = None
        self.cloud_pub: Any = None
        self.retry_timer: Any = None

    def p(self, name: str) -> Any:
        return self.get_parameter(name).value

    # --- transitions ---
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Configuring")
        try:
            values = {f: self.p(f) for f in vars(FilterParameters())}
            params = FilterParameters(**values)
        except (TypeError, ValueError) as exc:
            self.get_logger().error(f"Invalid parameters: {exc}")
            return TransitionCallbackReturn.FAILURE
        problem = params.check()
        for name in ("transform_tolerance", "update_min_a", "update_min_d"):
            value = float(self.p(name))
            if not problem and not (math.isfinite(value) and value >= 0.0):
                problem = f"{name} must be a number >= 0, not {value}"
        if problem:
            self.get_logger().error(f"Invalid parameter: {problem}; staying unconfigured")
            return TransitionCallbackReturn.FAILURE
        self.params = params
        self.map_frame = str(self.p("global_frame_id"))
        self.init_pose = (
            float(self.p("initial_pose.x")),
            float(self.p("initial_pose.y")),
            float(self.p("initial_pose.yaw")),
        )
        self.tf_buffer = Buffer(node=self)
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.tf_broadcaster = TransformBroadcaster(self)
        self.pose_pub = self.create_lifecycle_publisher(
            PoseWithCovarianceStamped, "amcl_pose", LATCHED
        )
        self.cloud_pub = self.create_lifecycle_publisher(ParticleCloud, "particle_cloud", CLOUD_QOS)
        self._made = [
            self.create_subscription(
                PoseWithCovarianceStamped, "initialpose", self.initial_pose_received, 10
            ),
            self.create_subscription(
                OccupancyGrid, str(self.p("map_topic")), self.map_received, LATCHED
            ),
            self.create_subscription(
                LaserScan, str(self.p("scan_topic")), self.laser_received, qos_profile_sensor_data
            ),
            self.create_service(
                Empty, "reinitialize_global_localization", self.global_localization_callback
            ),
            self.create_service(Empty, "request_nomotion_update", self.nomotion_update_callback),
            self.create_service(SetInitialPose, "set_initial_pose", self.set_initial_pose_callback),
        ]
        self.retry_timer = self.create_timer(0.02, self.retry_pending_scan)
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Activating")
        result = super().on_activate(state)
        self.active = True
        if self.p("set_initial_pose"):
            msg = PoseWithCovarianceStamped()
            msg.header.frame_id = self.map_frame
            msg.header.stamp = self.get_clock().now().to_msg()
            x, y, yaw = self.init_pose
            msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
            msg.pose.pose.position.z = float(self.p("initial_pose.z"))
            msg.pose.pose.orientation.z = math.sin(yaw / 2.0)
            msg.pose.pose.orientation.w = math.cos(yaw / 2.0)
            msg.pose.covariance[0], msg.pose.covariance[7] = DEFAULT_COV[0], DEFAULT_COV[1]
            msg.pose.covariance[35] = DEFAULT_COV[2]
            self.initial_pose_received(msg)
        return result

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Deactivating")
        self.active = False
        return super().on_deactivate(state)

    def release(self) -> None:
        self.active = False
        for thing in self._made:
            if hasattr(thing, "srv_type"):
                self.destroy_service(thing)
            else:
                self.destroy_subscription(thing)
        self._made = []
        if self.retry_timer is not None:
            self.destroy_timer(self.retry_timer)
            self.retry_timer = None
        if self.tf_listener is not None:
            self.tf_listener.unregister()
            self.tf_listener = None
        for pub in (self.pose_pub, self.cloud_pub):
            if pub is not None:
                self.destroy_lifecycle_publisher(pub)
        self.pose_pub = self.cloud_pub = None
        self.tf_buffer = None
        self.tf_broadcaster = None
        self.pf = None
        self.amcl_map = None
        self.first_map_received = self.initial_pose_known = self.pf_init = False
        self.latest_tf = None
        self.laser_poses = {}
        self.pending_scan = self.pending_initial_pose = None

    def _active(self) -> bool:
        return self._state_machine.current_state[0] == State.PRIMARY_STATE_ACTIVE

    # --- the map ---
    def map_received(self, msg: OccupancyGrid) -> None:
        if self.p("first_map_only") and self.first_map_received:
            return
        info = msg.info
        self.get_logger().info(
            f"Received a {info.width} X {info.height} map @ {info.resolution:.3f} m/pix"
        )
        if msg.header.frame_id != self.map_frame:
            self.get_logger().warning(
                f"Frame_id of map received:'{msg.header.frame_id}' doesn't match "
                f"global_frame_id:'{self.map_frame}'. This could cause issues with reading "
                "published topics"
            )
        if abs(yaw_of(info.origin.orientation)) > 1e-6:
            self.get_logger().warning("The map's origin is turned: amcl ignores the turn")
        try:
            amcl_map = AmclMap.from_occupancy(
                msg.data,
                info.width,
                info.height,
                info.resolution,
                (info.origin.position.x, info.origin.position.y),
            )
            amcl_map.update_cspace(self.params.laser_likelihood_max_dist)
            seed = int(self.p("random_seed"))
            pf = ParticleFilter(self.params, amcl_map, seed if seed >= 0 else None)
        except ValueError as exc:
            self.get_logger().error(f"Refusing the map: {exc}; keeping the one before (if any)")
            return
        if self.pf is not None:
            # As Nav2's handleMapMessage: a new map changes what the scans are weighed
            # against, never where the particles are. (Ours re-spread them round the
            # initial pose: a map delivered again mid-drive threw the estimate back there.)
            pf.take_particles(self.pf)
            self.amcl_map, self.pf = amcl_map, pf
            return
        self.amcl_map, self.pf = amcl_map, pf
        self.first_map_received = True
        pf.init_gaussian(self.init_pose, self.init_cov)
        self.pf_init = False
        self.latest_tf = None
        if self.p("always_reset_initial_pose"):
            self.initial_pose_known = False
        if self.pending_initial_pose is not None:  # it came before the map
            pending, self.pending_initial_pose = self.pending_initial_pose, None
            self.initial_pose_received(pending)

    # --- initial poses and services ---
    def initial_pose_received(self, msg: PoseWithCovarianceStamped) -> None:
        self.get_logger().info("initialPoseReceived")
        if msg.header.frame_id != self.map_frame:
            self.get_logger().warning(
                f'Ignoring initial pose in frame "{msg.header.frame_id}"; initial poses must be '
                f'in the global frame, "{self.map_frame}"'
            )
            return
        pose = msg.pose.pose
        x, y, yaw = pose.position.x, pose.position.y, yaw_of(pose.orientation)
        cov = np.array(msg.pose.covariance, np.float64).reshape(6, 6)
        c3 = np.array(
            [[cov[0, 0], cov[0, 1], 0.0], [cov[1, 0], cov[1, 1], 0.0], [0.0, 0.0, cov[5, 5]]]
        )
        if not (all(math.isfinite(v) for v in (x, y, yaw)) and np.isfinite(c3).all()):
            self.get_logger().warning("Ignoring initial pose: it has NaN or infinite values")
            return
        if self.pf is None or self.amcl_map is None:
            self.get_logger().info("Received an initial pose before a map: using it when one comes")
            self.pending_initial_pose = msg
            return
        if self.amcl_map.state_at(x, y) != FREE:
            self.get_logger().warning(
                f"Ignoring initial pose ({x:.3f}, {y:.3f}): it is not on a free cell of the map"
            )
            return
        self.get_logger().info(f"Setting pose: {x:.3f} {y:.3f} {yaw:.3f}")
        self.init_pose, self.init_cov = (x, y, yaw), c3
        self.pf.init_gaussian(self.init_pose, c3)
        self.pf_init = False
        self.initial_pose_known = True

    def global_localization_callback(self, request: Empty.Request, response: Any) -> Any:
        if self.pf is None:
            self.get_logger().warning("Global initialisation needs a map first: none received yet")
            return response
        self.get_logger().info("Initializing with uniform distribution")
        self.pf.init_uniform()
        self.get_logger().info("Global initialisation done!")
        self.initial_pose_known = True
        self.pf_init = False
        # Ours (Nav2 shows the spread with the next update): the spread at once. The product
        # of the beams (our laser model) gathers the particles from the first scan on.
        self.publish_particle_cloud(self.get_clock().now().to_msg())
        return response

    def nomotion_update_callback(self, request: Empty.Request, response: Any) -> Any:
        self.force_update = True
        self.get_logger().info("Requesting no-motion update")
        return response

    def set_initial_pose_callback(self, request: SetInitialPose.Request, response: Any) -> Any:
        self.initial_pose_received(request.pose)
        return response

    # --- scans ---
    def laser_received(self, msg: LaserScan) -> None:
        if not self.active or self.pf is None:
            return
        if not self.initial_pose_known:
            self.get_logger().warning(
                "AMCL cannot publish a pose or update the transform. "
                "Please set the initial pose...",
                throttle_duration_sec=5.0,
            )
            return
        if not self.process_scan(msg, final=False):
            self.pending_scan = msg  # its odometry is not on /tf yet: the timer tries again
            self.pending_since = time.monotonic()

    def retry_pending_scan(self) -> None:
        msg = self.pending_scan
        if msg is None or not self.active:
            return
        final = time.monotonic() - self.pending_since > PENDING_SCAN_AGE
        if self.process_scan(msg, final=final) or final:
            self.pending_scan = None

    def _lookup(self, target: str, source: str, stamp: Any) -> tuple[float, float, float] | None:
        assert self.tf_buffer is not None
        try:
            return pose2d(self.tf_buffer.lookup_transform(target, source, Time.from_msg(stamp)))
        except Exception:
            return None

    def process_scan(self, msg: LaserScan, final: bool) -> bool:
        """Update with one scan; False when its odometry is not known (yet)."""
        pf = self.pf
        if pf is None:
            return True
        odom, base = str(self.p("odom_frame_id")), str(self.p("base_frame_id"))
        frame = msg.header.frame_id
        if frame not in self.laser_poses:
            found = self._lookup(base, frame, Time().to_msg())
            if found is None:
                if final:
                    self.get_logger().error(
                        f"Couldn't transform from {frame} to {base}, even though the message "
                        "notifier is in use"
                    )
                return False
            self.laser_poses[frame] = found
        pose = self._lookup(odom, base, msg.header.stamp)
        if pose is None:
            if final:
                self.get_logger().error(
                    "Couldn't determine robot's pose associated with laser scan",
                    throttle_duration_sec=5.0,
                )
            return False
        started, started_cpu = time.perf_counter(), time.thread_time()
        update = self.force_update
        if self.pf_init:
            dx = pose[0] - self.pf_odom_pose[0]
            dy = pose[1] - self.pf_odom_pose[1]
            dyaw = angle_diff(pose[2], self.pf_odom_pose[2])
            update = update or (
                abs(dx) > float(self.p("update_min_d"))
                or abs(dy) > float(self.p("update_min_d"))
                or abs(dyaw) > float(self.p("update_min_a"))
            )
        force_publication = False
        resampled = False
        if not self.pf_init:
            self.pf_odom_pose = pose
            self.pf_init = True
            force_publication = True
            pf.resample_count = 0
        elif update:
            delta = (
                pose[0] - self.pf_odom_pose[0],
                pose[1] - self.pf_odom_pose[1],
                angle_diff(pose[2], self.pf_odom_pose[2]),
            )
            pf.update_action(pose, delta)
            self.force_update = False
            range_max = msg.range_max
            if self.params.laser_max_range > 0.0:
                range_max = min(range_max, self.params.laser_max_range)
            range_min = max(msg.range_min, self.params.laser_min_range)
            beams = ScanBeams.from_scan(
                np.asarray(msg.ranges, np.float64),
                msg.angle_min,
                msg.angle_increment,
                range_min,
                range_max,
                self.params.max_beams,
                self.laser_poses[frame],
            )
            resampled = pf.update(beams)
            self.pf_odom_pose = pose
            self.publish_particle_cloud(msg.header.stamp)
            force_publication = True
        if resampled or force_publication:
            estimate = pf.estimate()
            if estimate.weight > 0.0:
                self.publish_amcl_pose(msg, estimate)
                map_base = (estimate.x, estimate.y, estimate.yaw)
                self.latest_tf = compose(map_base, inverse(pose))
        if self.latest_tf is not None and self.p("tf_broadcast"):
            self.send_map_to_odom(msg)
        if update:
            self.last_update_ms = (time.perf_counter() - started) * 1e3
            cpu_ms = (time.thread_time() - started_cpu) * 1e3  # without the waits on a busy machine
            self.get_logger().debug(
                f"filter update: {self.last_update_ms:.1f} ms ({cpu_ms:.1f} ms CPU) with "
                f"{pf.count} particles"
            )
        return True

    # --- output ---
    def publish_particle_cloud(self, stamp: Any) -> None:
        if self.pf is None or self.cloud_pub is None:
            return
        # Written from the filter's arrays as bytes (nav2_amcl.cloud): the same message as
        # ParticleCloud(particles=[Particle(...), ...]), without 2000 Python objects a time.
        cloud = particle_cloud_cdr(
            stamp.sec, stamp.nanosec, self.map_frame, self.pf.poses, self.pf.weights
        )
        self.cloud_pub.publish(cloud)

    def publish_amcl_pose(self, scan: LaserScan, estimate: Any) -> None:
        if self.pose_pub is None:
            return
        msg = PoseWithCovarianceStamped()
        msg.header.stamp = scan.header.stamp
        msg.header.frame_id = self.map_frame
        msg.pose.pose.position.x, msg.pose.pose.position.y = estimate.x, estimate.y
        msg.pose.pose.orientation.z = math.sin(estimate.yaw / 2.0)
        msg.pose.pose.orientation.w = math.cos(estimate.yaw / 2.0)
        cov = estimate.covariance
        covariance = [0.0] * 36
        covariance[0], covariance[1] = float(cov[0, 0]), float(cov[0, 1])
        covariance[6], covariance[7] = float(cov[1, 0]), float(cov[1, 1])
        covariance[35] = float(cov[2, 2])
        msg.pose.covariance = covariance
        self.pose_pub.publish(msg)
        self.get_logger().debug(
            f"New pose: {estimate.x:.3f} {estimate.y:.3f} {estimate.yaw:.3f} "
            f"({estimate.clusters} clusters)"
        )

    def send_map_to_odom(self, scan: LaserScan) -> None:
        assert self.latest_tf is not None and self.tf_broadcaster is not None
        x, y, yaw = self.latest_tf
        t = TransformStamped()
        stamp = Time.from_msg(scan.header.stamp) + Duration(
            seconds=float(self.p("transform_tolerance"))
        )
        t.header.stamp = stamp.to_msg()
        t.header.frame_id = self.map_frame
        t.child_frame_id = str(self.p("odom_frame_id"))
        t.transform.translation.x, t.transform.translation.y = x, y
        t.transform.rotation.z = math.sin(yaw / 2.0)
        t.transform.rotation.w = math.cos(yaw / 2.0)
        self.tf_broadcaster.sendTransform(t)


def main(args: list[str] | None = None) -> int:
    node: AmclNode | None = None
    try:
        try:
            rclpy.init(args=args)
        except Exception as exc:  # rcl refuses the arguments
            print(f"amcl: error: {exc}", file=sys.stderr)
            return 1
        node = AmclNode()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
