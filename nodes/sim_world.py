"""sim_world: a MuJoCo world with a differential-drive robot and an arm, as Gazebo would run it.

It steps the physics of ``nodes/worlds/<world>/world.xml`` in real time (or
``real_time_factor`` times faster or slower) and publishes what a real robot's
drivers publish, stamped with simulation time:

- ``/clock`` (rosgraph_msgs/Clock): run other nodes with ``use_sim_time:=true``;
- ``/cmd_vel`` in (geometry_msgs/Twist): the base drives at that velocity until
  ``cmd_vel_timeout`` seconds pass without a new command, then stops;
- ``/odom`` (nav_msgs/Odometry) and ``odom -> base_link`` on ``/tf``: dead
  reckoning from the wheel encoders (it drifts, as on a real robot);
- ``world -> odom`` on ``/tf``: the odometry's error, so that world -> odom ->
  base_link is where the robot really is (what a localization node publishes
  as map -> odom on a real robot; here the simulator knows the truth). With
  ``publish_world_tf:=false`` it is left out, so that a mapping or
  localization node's ``map -> odom`` is odom's only parent (TF is a tree);
- ``/ground_truth/odom`` (nav_msgs/Odometry, frame ``world``): where the robot
  really is, for lessons to compare with;
- ``/scan`` (sensor_msgs/LaserScan, 360 rays at 10 Hz, noisy), ``/imu``
  (sensor_msgs/Imu), ``/camera/image_raw`` + ``/camera/camera_info`` (320x240
  at 15 Hz, rendered in a thread of its own so the physics keeps time, and
  only while something subscribes to the picture);
- ``/joint_states``: the wheels, the arm's joints and its fingers;
- ``/arm_controller/joint_trajectory`` in (trajectory_msgs/JointTrajectory)
  and ``/gripper/command`` in (std_msgs/Float64, finger opening in metres);
- services as Gazebo's: ``/pause_physics``, ``/unpause_physics``,
  ``/reset_simulation`` (time back to 0), ``/reset_world`` (time goes on), all
  std_srvs/Empty, and ``/step_simulation`` (std_srvs/Trigger, advances
  ``step_duration`` seconds while paused);
- ``world -> arm_base_link`` on ``/tf_static``: where the world file bolted the arm;
- ``~/static_markers`` and ``~/object_markers`` (visualization_msgs/MarkerArray,
  frame ``world``, latched): the world itself for a 3D view or rviz, built from
  the same model the physics steps. The static one (floor, walls, furniture)
  is sent once; the loose objects are sent again whenever one moves (at most
  15 times a simulated second). The robots are not in them: they are drawn
  from their URDF (robot_state_publisher) at their TF frames;
- ``/real_time_factor`` (std_msgs/Float64, once a wall-clock second): simulated
  seconds per wall-clock second, measured since the report before (what the
  world achieved: less than ``real_time_factor`` asks when the computer cannot
  keep up, 0 while paused). Each report is sent the moment it is measured, so
  its source timestamp ends the span it covers (the ``sim_time_factor`` lesson
  check pairs it with ``/clock`` on that clock).

Bad input never stops the world: a non-finite velocity is ignored, a too fast
one clamped, a trajectory with unknown joints refused, each with a log line
that says why. A world file that does not load stops the node at start with
the reason.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, TransformStamped, Twist
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, Image, Imu, JointState, LaserScan
from std_msgs.msg import ColorRGBA, Float64
from std_srvs.srv import Empty, Trigger
from tf2_msgs.msg import TFMessage
from trajectory_msgs.msg import JointTrajectory
from visualization_msgs.msg import Marker, MarkerArray

from nodes.common.run import spin_node
from nodes.common.sim import GL_BACKEND, send_warnings_to
from nodes.common.sim.camera import SnapshotCamera, intrinsics
from nodes.common.sim.diff_drive import Odometry as WheelOdometry
from nodes.common.sim.diff_drive import check_twist, odom_in_world, quantize
from nodes.common.sim.engine import Pose2D, SimEngine
from nodes.common.sim.trajectory import TrajectoryError
from nodes.common.sim.world_geometry import Primitive, WorldGeometry

MAX_LAG = 1.0  # s of simulation behind schedule before the world gives up catching up
# Integer parameters a start-up cannot use: refused with the reason (exit status 2).
INTEGER_RANGES = {
    "encoder_ticks": (1, 1 << 20),
    "camera_width": (16, 1920),
    "camera_height": (16, 1080),
}
CHUNK = 50  # physics steps between two looks at the clock when running flat out
OBJECTS_RATE = 15.0  # Hz of simulation time: how often moved objects are sent again
ROBOT_ROOTS = ("base_link", "arm_base_link")  # drawn from their URDFs, not as markers
MARKER_KINDS = {
    "cube": Marker.CUBE,
    "sphere": Marker.SPHERE,
    "cylinder": Marker.CYLINDER,
    "triangles": Marker.TRIANGLE_LIST,
}


def stamp(seconds: float) -> Time:
    sec = math.floor(seconds)
    return Time(sec=int(sec), nanosec=int((seconds - sec) * 1e9))


def marker_of(shape: Primitive, at: Time) -> Marker:
    """A shape of the world as the Marker rviz (and the dashboard's 3D view) draws."""
    marker = Marker(ns=shape.ns, id=shape.id, type=MARKER_KINDS[shape.kind], action=Marker.ADD)
    marker.header.stamp = at
    marker.header.frame_id = "world"
    position, orientation = marker.pose.position, marker.pose.orientation
    position.x, position.y, position.z = shape.position
    orientation.x, orientation.y, orientation.z, orientation.w = shape.quat_xyzw
    marker.scale.x, marker.scale.y, marker.scale.z = shape.scale
    r, g, b, a = shape.rgba
    marker.color = ColorRGBA(r=r, g=g, b=b, a=a)
    if shape.triangles is not None:
        marker.points = [Point(x=float(x), y=float(y), z=float(z)) for x, y, z in shape.triangles]
    return marker


def _range(low: float, high: float, text: str) -> ParameterDescriptor:
    return ParameterDescriptor(
        description=text,
        floating_point_range=[FloatingPointRange(from_value=low, to_value=high)],
    )


class SimWorld(Node):
    def __init__(self) -> None:
        super().__init__("sim_world")
        p = self.declare_parameter
        p("world", "room", ParameterDescriptor(description="nodes/worlds/<name> or an .xml path"))
        p("x", 0.0, _range(-100.0, 100.0, "start x of the robot (m), used at each reset"))
        p("y", 0.0, _range(-100.0, 100.0, "start y of the robot (m), used at each reset"))
        p("yaw", 0.0, _range(-math.pi, math.pi, "start heading (rad), used at each reset"))
        p("real_time_factor", 1.0, _range(0.0, 100.0, "sim s per wall s; 0: as fast as it can"))
        p("cmd_vel_timeout", 0.5, _range(0.05, 10.0, "s without /cmd_vel before the base stops"))
        p("max_linear_velocity", 0.5, _range(0.0, 2.0, "m/s, faster commands are clamped"))
        p("max_angular_velocity", 2.5, _range(0.0, 10.0, "rad/s, faster commands are clamped"))
        # The driver's calibration: close to the true 0.033 m and 0.16 m, never equal.
        p("wheel_radius", 0.0332, _range(0.01, 0.1, "m, as the base driver believes"))
        p("wheel_separation", 0.163, _range(0.05, 0.5, "m, as the base driver believes"))
        p("encoder_ticks", 4096)
        p("odom_rate", 30.0, _range(1.0, 200.0, "Hz of /odom, /tf, /joint_states, ground truth"))
        p("imu_rate", 50.0, _range(1.0, 500.0, "Hz"))
        p("scan_rate", 10.0, _range(1.0, 50.0, "Hz"))
        p("clock_rate", 100.0, _range(10.0, 1000.0, "Hz of /clock in simulation time"))
        p("camera_rate", 15.0, _range(0.0, 60.0, "Hz; 0 turns the camera off"))
        p("camera_width", 320)
        p("camera_height", 240)
        p("step_duration", 0.1, _range(0.001, 10.0, "s that /step_simulation advances"))
        p("seed", 0)
        p(
            "publish_world_tf",
            True,
            ParameterDescriptor(
                description="world -> odom on /tf; false when a mapping or localization node "
                "publishes map -> odom (odom may have one parent only)"
            ),
        )
        g = self._param
        for name, (low, high) in INTEGER_RANGES.items():
            if not low <= int(g(name)) <= high:
                raise ValueError(f"parameter {name} = {g(name)} is outside {low}..{high}")
        self.engine = SimEngine(
            str(g("world")),
            start=self._start_pose(),
            drive_radius=float(g("wheel_radius")),
            drive_separation=float(g("wheel_separation")),
            seed=int(g("seed")),
        )  # a world that does not load raises WorldError: the node stops with the reason
        if not self.engine.has_mobile:
            raise ValueError(
                f"world {g('world')!r} has no diffbot (joints base_free, *_wheel_joint)"
            )
        send_warnings_to(self.on_mujoco_warning)
        self.rng = np.random.default_rng(int(g("seed")) + 1)
        self.ticks = int(g("encoder_ticks"))
        self.odometry = WheelOdometry(float(g("wheel_radius")), float(g("wheel_separation")))
        self.odometry.reset(*self._encoders())
        self.lock = threading.Lock()
        self.stopping = threading.Event()
        self.paused = False
        self.pending_steps = 0
        self.steps_done = threading.Condition(self.lock)
        self.rtf_target = float(g("real_time_factor"))
        self.reanchor = True
        self.command = (0.0, 0.0)
        self.command_time = -math.inf
        self.rtf_measured = 0.0
        self.cmd_vel_timeout = float(g("cmd_vel_timeout"))
        self.publish_world_tf = bool(g("publish_world_tf"))

        self.clock_pub = self.create_publisher(Clock, "/clock", 10)
        self.odom_pub = self.create_publisher(Odometry, "odom", 10)
        self.truth_pub = self.create_publisher(Odometry, "ground_truth/odom", 10)
        self.tf_pub = self.create_publisher(TFMessage, "/tf", 100)
        self.joint_pub = self.create_publisher(JointState, "joint_states", 10)
        self.imu_pub = self.create_publisher(Imu, "imu", 10)
        self.scan_pub = self.create_publisher(LaserScan, "scan", 10)
        self.image_pub = self.create_publisher(Image, "camera/image_raw", 5)
        self.info_pub = self.create_publisher(CameraInfo, "camera/camera_info", 5)
        self.rtf_pub = self.create_publisher(Float64, "real_time_factor", 10)
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.static_tf_pub = self.create_publisher(TFMessage, "/tf_static", latched)
        if self.engine.has_arm:  # the arm is bolted to its table: world -> arm_base_link
            self.static_tf_pub.publish(TFMessage(transforms=[self.arm_mount()]))
        # The world as markers, from the model the physics steps (robots: their URDFs).
        roots = [name for name in ROBOT_ROOTS if self._has_body(name)]
        self.geometry = WorldGeometry(self.engine.model, roots)
        self.static_markers_pub = self.create_publisher(MarkerArray, "~/static_markers", latched)
        self.object_markers_pub = self.create_publisher(MarkerArray, "~/object_markers", latched)
        self.publish_static_markers()
        self.publish_objects(self.engine.time)
        for reason in self.geometry.skipped:
            self.get_logger().warning(f"not in the markers: {reason}")

        self.create_subscription(Twist, "cmd_vel", self.on_cmd_vel, 10)
        self.create_subscription(
            JointTrajectory, "arm_controller/joint_trajectory", self.on_trajectory, 10
        )
        self.create_subscription(Float64, "gripper/command", self.on_gripper, 10)
        self.create_service(Empty, "pause_physics", self.on_pause)
        self.create_service(Empty, "unpause_physics", self.on_unpause)
        self.create_service(Empty, "reset_simulation", self.on_reset_simulation)
        self.create_service(Empty, "reset_world", self.on_reset_world)
        self.create_service(Trigger, "step_simulation", self.on_step)
        self.add_on_set_parameters_callback(self.on_parameters)
        self.rtf_timer = self.create_timer(1.0, self.on_rtf_timer)

        # Sensor streams, each due at a multiple of its period in simulation time.
        self.streams: list[list] = []
        for rate, publish in (
            (g("clock_rate"), self.publish_clock),
            (g("odom_rate"), self.publish_odometry),
            (g("imu_rate"), self.publish_imu),
            (g("scan_rate"), self.publish_scan),
            (OBJECTS_RATE, self.publish_objects),
        ):
            self.streams.append([1.0 / float(rate), 0.0, publish])
        self.camera_request: tuple[float, np.ndarray] | None = None
        self.camera_wake = threading.Event()
        self.threads = [threading.Thread(target=self.run_physics, name="physics", daemon=True)]
        self.rtf_wall, self.rtf_sim = time.monotonic(), self.engine.time
        for thread in self.threads:
            thread.start()
        if float(g("camera_rate")) > 0:
            self.set_camera_rate(float(g("camera_rate")))
        self.get_logger().info(
            f"world {g('world')!r} loaded: timestep {self.engine.timestep * 1000:g} ms, "
            f"real_time_factor {self.rtf_target:g}, camera rendering through "
            f"{GL_BACKEND or 'no OpenGL found'}"
        )

    def arm_mount(self) -> TransformStamped:
        """Where the world file put the arm's base (a fixed transform, as a URDF's fixed joint)."""
        position, quat = self.engine.body_pose("arm_base_link")
        mount = TransformStamped()
        mount.header.stamp = stamp(self.engine.time)
        mount.header.frame_id = "world"
        mount.child_frame_id = "arm_base_link"
        t, r = mount.transform.translation, mount.transform.rotation
        t.x, t.y, t.z = (float(v) for v in position)
        r.x, r.y, r.z, r.w = (float(v) for v in quat)
        return mount

    def _has_body(self, name: str) -> bool:
        try:
            self.engine.model.body(name)
        except KeyError:
            return False
        return True

    def on_mujoco_warning(self, text: str) -> None:
        """MuJoCo's warnings go to the log (its own handler writes MUJOCO_LOG.TXT in the cwd)."""
        self.get_logger().warning(f"MuJoCo: {' '.join(text.split())}")

    def _param(self, name: str):
        return self.get_parameter(name).value

    def _start_pose(self) -> Pose2D:
        return Pose2D(float(self._param("x")), float(self._param("y")), float(self._param("yaw")))

    def _encoders(self) -> tuple[float, float]:
        left, right = self.engine.encoders()
        return quantize(left, self.ticks), quantize(right, self.ticks)

    # --- the physics thread ------------------------------------------------------------
    def run_physics(self) -> None:
        self._quietly_at_shutdown(self.physics_loop)

    def _quietly_at_shutdown(self, loop: Callable[[], None]) -> None:
        """Ctrl+C shuts ROS down before the threads stop: a publish may fail then, quietly."""
        try:
            loop()
        except Exception:
            if self.context.ok() and not self.stopping.is_set():
                raise

    def physics_loop(self) -> None:
        """Step in time with the wall clock (scaled), publishing each stream when it is due."""
        dt = self.engine.timestep
        anchor_wall = anchor_sim = 0.0
        while not self.stopping.is_set():
            with self.lock:
                if self.reanchor:
                    anchor_wall, anchor_sim = time.monotonic(), self.engine.time
                    self.reanchor = False
                if self.paused:
                    count = self.pending_steps
                elif self.rtf_target <= 0.0:
                    count = CHUNK
                else:
                    behind = anchor_sim + (time.monotonic() - anchor_wall) * self.rtf_target
                    behind -= self.engine.time
                    if behind > MAX_LAG:  # cannot keep up: drop the lost time, run on from here
                        anchor_wall, anchor_sim = time.monotonic(), self.engine.time
                        behind = 0.0
                    count = min(int(behind / dt), CHUNK)
                for _ in range(count):
                    self.step_once()
                if self.paused and count:
                    self.pending_steps = 0
                    self.steps_done.notify_all()
            if count == 0 or self.paused:
                wait = dt / self.rtf_target if self.rtf_target > 0 and not self.paused else 0.005
                self.stopping.wait(min(wait, 0.005))

    def step_once(self) -> None:
        engine = self.engine
        if engine.time - self.command_time > self.cmd_vel_timeout:
            self.command = (0.0, 0.0)
        engine.drive(*self.command)
        engine.step(1)
        now = engine.time
        for stream in self.streams:
            if now + 1e-9 >= stream[1]:
                period = stream[0]
                stream[1] = (math.floor(now / period + 1e-6) + 1) * period
                stream[2](now)

    # --- publishing (physics thread, under the lock) ------------------------------------
    def publish_clock(self, now: float) -> None:
        self.clock_pub.publish(Clock(clock=stamp(now)))

    def publish_odometry(self, now: float) -> None:
        engine, odom = self.engine, self.odometry
        odom.update(*self._encoders(), dt=self.streams[1][0])
        header_stamp = stamp(now)
        msg = Odometry()
        msg.header.stamp = header_stamp
        msg.header.frame_id = "odom"
        msg.child_frame_id = "base_link"
        msg.pose.pose.position.x, msg.pose.pose.position.y = odom.x, odom.y
        msg.pose.pose.orientation.z = math.sin(odom.yaw / 2.0)
        msg.pose.pose.orientation.w = math.cos(odom.yaw / 2.0)
        msg.twist.twist.linear.x, msg.twist.twist.angular.z = odom.linear, odom.angular
        msg.pose.covariance[0] = msg.pose.covariance[7] = msg.pose.covariance[35] = 0.001
        msg.twist.covariance[0] = msg.twist.covariance[35] = 0.001
        self.odom_pub.publish(msg)
        tf = TransformStamped()
        tf.header = msg.header
        tf.child_frame_id = "base_link"
        tf.transform.translation.x, tf.transform.translation.y = odom.x, odom.y
        tf.transform.rotation = msg.pose.pose.orientation
        position, quat = engine.base_pose()
        correction = TransformStamped()  # world -> odom: the truth minus the odometry
        correction.header.stamp = header_stamp
        correction.header.frame_id = "world"
        correction.child_frame_id = "odom"
        where, turn = odom_in_world(position, quat, odom.x, odom.y, odom.yaw)
        t, r = correction.transform.translation, correction.transform.rotation
        t.x, t.y, t.z = where
        r.x, r.y, r.z, r.w = turn
        transforms = [correction, tf] if self.publish_world_tf else [tf]
        self.tf_pub.publish(TFMessage(transforms=transforms))

        truth = Odometry()
        truth.header.stamp = header_stamp
        truth.header.frame_id = "world"
        truth.child_frame_id = "base_link"
        linear, angular = engine.base_velocity()
        pose = truth.pose.pose
        pose.position.x, pose.position.y, pose.position.z = (float(v) for v in position)
        q = pose.orientation
        q.x, q.y, q.z, q.w = (float(v) for v in quat)
        tw = truth.twist.twist
        tw.linear.x, tw.linear.y, tw.linear.z = (float(v) for v in linear)
        tw.angular.x, tw.angular.y, tw.angular.z = (float(v) for v in angular)
        self.truth_pub.publish(truth)

        names, positions, velocities = engine.joint_state()
        joints = JointState(name=list(names), position=positions.tolist())
        joints.velocity = velocities.tolist()
        joints.header.stamp = header_stamp
        self.joint_pub.publish(joints)

    def publish_static_markers(self) -> None:
        at = stamp(self.engine.time)
        clear = Marker(action=Marker.DELETEALL)  # a world loaded before this one goes
        clear.header.frame_id = "world"
        shapes = self.geometry.static_primitives(self.engine.data)
        markers = [clear, *(marker_of(shape, at) for shape in shapes)]
        self.static_markers_pub.publish(MarkerArray(markers=markers))

    def publish_objects(self, now: float) -> None:
        """Every loose object, when one has moved (the latched message stays complete)."""
        if not self.geometry.objects_moved(self.engine.data):
            return
        at = stamp(now)
        shapes = self.geometry.object_primitives(self.engine.data)
        self.object_markers_pub.publish(MarkerArray(markers=[marker_of(s, at) for s in shapes]))

    def publish_imu(self, now: float) -> None:
        quat, gyro, accel = self.engine.imu()
        gyro = gyro + self.rng.normal(0.0, 0.002, 3)
        accel = accel + self.rng.normal(0.0, 0.02, 3)
        msg = Imu()
        msg.header.stamp = stamp(now)
        msg.header.frame_id = "imu_link"
        o = msg.orientation
        o.x, o.y, o.z, o.w = (float(v) for v in quat)
        av, la = msg.angular_velocity, msg.linear_acceleration
        av.x, av.y, av.z = (float(v) for v in gyro)
        la.x, la.y, la.z = (float(v) for v in accel)
        for k in (0, 4, 8):
            msg.orientation_covariance[k] = 1e-4
            msg.angular_velocity_covariance[k] = 0.002**2
            msg.linear_acceleration_covariance[k] = 0.02**2
        self.imu_pub.publish(msg)

    def publish_scan(self, now: float) -> None:
        lidar = self.engine.lidar
        assert lidar is not None
        ranges = lidar.measure(self.engine.data)
        period = 1.0 / float(self._param("scan_rate"))
        msg = LaserScan()
        msg.header.stamp = stamp(now)
        msg.header.frame_id = "lidar_link"
        msg.angle_min = float(lidar.angles[0])
        msg.angle_increment = 2.0 * math.pi / lidar.count
        msg.angle_max = float(lidar.angles[-1])
        msg.scan_time = period
        msg.time_increment = period / lidar.count
        msg.range_min, msg.range_max = lidar.range_min, lidar.range_max
        msg.ranges = ranges.astype(np.float32)
        self.scan_pub.publish(msg)

    def request_frame(self, now: float) -> None:
        """Hand the camera thread a copy of the state; a frame still rendering makes it skip."""
        self.camera_request = (now, self.engine.snapshot())
        self.camera_wake.set()

    # --- the camera thread ---------------------------------------------------------------
    def run_camera(self) -> None:
        self._quietly_at_shutdown(self.camera_loop)

    def camera_loop(self) -> None:
        width, height = int(self._param("camera_width")), int(self._param("camera_height"))
        try:
            camera = SnapshotCamera(self.engine.model, "camera", width, height)
        except Exception as exc:  # no OpenGL here: the world runs on without a camera
            self.get_logger().error(
                f"camera disabled, rendering through MUJOCO_GL={GL_BACKEND or '(none)'} "
                f"failed: {exc} (make setup installs Mesa's EGL and OSMesa)"
            )
            return
        fovy = float(self.engine.model.cam_fovy[self.engine.model.camera("camera").id])
        info = CameraInfo(width=width, height=height, distortion_model="plumb_bob")
        k = intrinsics(width, height, fovy)
        info.k = k.ravel().tolist()
        info.d = [0.0] * 5
        info.r = np.eye(3).ravel().tolist()
        info.p = np.hstack([k, np.zeros((3, 1))]).ravel().tolist()
        info.header.frame_id = "camera_optical_frame"
        try:
            while not self.stopping.is_set():
                if not self.camera_wake.wait(0.1):
                    continue
                self.camera_wake.clear()
                request, self.camera_request = self.camera_request, None
                if request is None:
                    continue
                now, qpos = request
                info.header.stamp = stamp(now)
                # A picture nobody reads is not drawn, as Gazebo's cameras do: software
                # rendering is most of an idle world's CPU (a class's server holds many).
                if self.image_pub.get_subscription_count() > 0:
                    image = Image(height=height, width=width, encoding="rgb8", step=width * 3)
                    image.header.stamp = info.header.stamp
                    image.header.frame_id = "camera_optical_frame"
                    image.data = camera.render(qpos).tobytes()
                    self.image_pub.publish(image)
                if self.info_pub.get_subscription_count() > 0:
                    self.info_pub.publish(info)
        finally:
            camera.close()

    # --- commands (executor thread) ---------------------------------------------------------
    def on_cmd_vel(self, msg: Twist) -> None:
        checked = check_twist(
            msg.linear.x,
            msg.angular.z,
            float(self._param("max_linear_velocity")),
            float(self._param("max_angular_velocity")),
        )
        if checked.problem:
            self.get_logger().warning(checked.problem, throttle_duration_sec=2.0)
        if checked.rejected:
            return
        with self.lock:
            self.command = (checked.linear, checked.angular)
            self.command_time = self.engine.time

    def on_trajectory(self, msg: JointTrajectory) -> None:
        points = [
            (list(p.positions), p.time_from_start.sec + p.time_from_start.nanosec * 1e-9)
            for p in msg.points
        ]
        with self.lock:
            try:
                plan = self.engine.command_trajectory(list(msg.joint_names), points)
            except TrajectoryError as exc:
                self.get_logger().error(f"rejected a joint trajectory: {exc}")
                return
        self.get_logger().info(
            f"following a trajectory of {len(points)} point(s) over {plan.duration:.2f} s"
        )

    def on_gripper(self, msg: Float64) -> None:
        if not math.isfinite(msg.data):
            self.get_logger().warning(f"ignored a gripper command of {msg.data} m")
            return
        with self.lock:
            opening = self.engine.set_gripper(msg.data)
        if abs(opening - msg.data) > 1e-9:
            self.get_logger().warning(
                f"gripper opening {msg.data:g} m is outside 0..0.09 m: set to {opening:g} m"
            )

    # --- services (executor thread) ---------------------------------------------------------
    def on_pause(self, request: Empty.Request, response: Empty.Response) -> Empty.Response:
        with self.lock:
            self.paused = True
        return response

    def on_unpause(self, request: Empty.Request, response: Empty.Response) -> Empty.Response:
        with self.lock:
            self.paused, self.reanchor = False, True
        return response

    def _reset(self, keep_time: bool) -> None:
        with self.lock:
            self.engine.reset(self._start_pose(), keep_time=keep_time)
            self.odometry.reset(*self._encoders())
            self.command, self.command_time = (0.0, 0.0), -math.inf
            for stream in self.streams:
                stream[1] = self.engine.time
            self.reanchor = True
        what = "world" if keep_time else "simulation (time back to 0)"
        self.get_logger().info(f"reset the {what}; robot at {self._start_pose()}")

    def on_reset_simulation(self, request: Empty.Request, response: Empty.Response):
        self._reset(keep_time=False)
        return response

    def on_reset_world(self, request: Empty.Request, response: Empty.Response):
        self._reset(keep_time=True)
        return response

    def on_step(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        with self.lock:
            if not self.paused:
                response.success = False
                response.message = "the simulation is running: call /pause_physics first"
                return response
            start = self.engine.time
            self.pending_steps = max(
                1, round(float(self._param("step_duration")) / self.engine.timestep)
            )
            done = self.steps_done.wait_for(lambda: self.pending_steps == 0, timeout=10.0)
            now = self.engine.time
        response.success = bool(done)
        response.message = f"stepped from t={start:.3f} s to t={now:.3f} s"
        return response

    def on_parameters(self, params: list[Parameter]) -> SetParametersResult:
        for param in params:
            if param.name == "real_time_factor":
                value = float(param.value)
                if not math.isfinite(value) or value < 0:
                    return SetParametersResult(successful=False, reason="must be >= 0")
                with self.lock:
                    self.rtf_target, self.reanchor = value, True
                self.get_logger().info(f"real_time_factor set to {value:g}")
            elif param.name == "cmd_vel_timeout":
                self.cmd_vel_timeout = float(param.value)
            elif param.name == "camera_rate":
                self.set_camera_rate(float(param.value))
                self.get_logger().info(f"camera_rate set to {float(param.value):g} Hz")
        return SetParametersResult(successful=True)

    def set_camera_rate(self, rate: float) -> None:
        """0 stops rendering (a grader running the world fast needs no pictures), > 0 resumes."""
        with self.lock:
            self.streams = [s for s in self.streams if s[2] != self.request_frame]
            if rate > 0:
                self.streams.append([1.0 / rate, self.engine.time, self.request_frame])
        if rate > 0 and not any(t.name == "camera" for t in self.threads):
            camera = threading.Thread(target=self.run_camera, name="camera", daemon=True)
            self.threads.append(camera)
            camera.start()

    def on_rtf_timer(self) -> None:
        """Simulated s per wall s since the last report: both clocks read, and the report
        sent, while the physics stands still (the lock), so the report's source timestamp
        (the middleware's, on this wall clock) marks the end of exactly the span it measured.
        Wall time read before waiting for the lock put a busy world's reports off by up
        to 2x either way (0.40x reported for 0.78x, 2.09x for 1.49x)."""
        with self.lock:
            now_wall, now_sim = time.monotonic(), self.engine.time
            wall = now_wall - self.rtf_wall
            self.rtf_measured = max(0.0, (now_sim - self.rtf_sim) / wall) if wall > 0 else 0.0
            self.rtf_wall, self.rtf_sim = now_wall, now_sim
            self.rtf_pub.publish(Float64(data=self.rtf_measured))

    def stop(self) -> None:
        """End the physics and camera threads (spin_node calls it before shutdown)."""
        self.stopping.set()
        self.camera_wake.set()
        for thread in self.threads:
            thread.join(timeout=5.0)


def _stop(node: SimWorld) -> None:
    node.stop()


def main(args: list[str] | None = None) -> None:
    spin_node(SimWorld, args, before_shutdown=_stop, program="sim_world")


if __name__ == "__main__":
    main()
