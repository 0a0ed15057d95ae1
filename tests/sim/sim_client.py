"""A program written against Gazebo-style robot topics, run against sim_world from outside.

It imports rclpy and message packages only, never the project's code, and is
started with a clean PYTHONPATH from another folder. It drives ``/sim_world``
through its interfaces and measures what happens; test_sim_world_ros.py judges
the numbers. Prints one JSON object (the last line of stdout): one key per
scenario.
"""

from __future__ import annotations

import json
import math
import re
import sys
import threading
import time
from typing import Any

import rclpy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import Log, Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter as RclpyParameter
from rclpy.qos import DurabilityPolicy, QoSProfile
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, Image, Imu, JointState, LaserScan
from std_msgs.msg import Float64, String
from std_srvs.srv import Empty, Trigger
from tf2_msgs.msg import TFMessage
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
from visualization_msgs.msg import MarkerArray

TIMEOUT = 25.0
ARM = ["base_yaw", "shoulder_pitch", "elbow_pitch", "wrist_pitch"]


def wait(predicate, timeout: float = TIMEOUT, what: str = "") -> Any:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.01)
    raise TimeoutError(f"timed out waiting for {what or predicate}")


def seconds(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def sim_at(samples: list[tuple[float, float]], wall: float) -> float:
    """Simulation time at a wall time, from the (wall, sim) /clock samples either side."""
    after = next(i for i, (w, _) in enumerate(samples) if w >= wall)
    if after == 0:
        return samples[0][1]
    (wa, sa), (wb, sb) = samples[after - 1], samples[after]
    return sa + (sb - sa) * (wall - wa) / (wb - wa)


class SimClient(Node):
    def __init__(self) -> None:
        super().__init__("sim_test_client")
        self.lock = threading.Lock()
        self.last: dict[str, Any] = {}
        self.arrivals: dict[str, list[float]] = {}  # stamps in simulation time (or arrivals)
        # /clock as (publication time by the publisher's wall clock, simulation time).
        self.clock_samples: list[tuple[float, float]] = []
        self.logs: list[str] = []
        topics = {
            "/clock": Clock,
            "/odom": Odometry,
            "/ground_truth/odom": Odometry,
            "/tf": TFMessage,
            "/scan": LaserScan,
            "/imu": Imu,
            "/joint_states": JointState,
            "/camera/image_raw": Image,
            "/camera/camera_info": CameraInfo,
            "/real_time_factor": Float64,
        }
        for topic, kind in topics.items():
            self.create_subscription(kind, topic, self._keeper(topic), 10)
        self.create_subscription(Clock, "/clock", self.on_clock, 100)
        # /real_time_factor as (publication time by the world's wall clock, factor reported).
        self.reports: list[tuple[float, float]] = []
        self.create_subscription(Float64, "/real_time_factor", self.on_report, 10)
        self.create_subscription(Log, "/rosout", self.on_log, 100)
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        # /tf_static has several latched writers (sim_world's mount, each robot's
        # robot_state_publisher): a late joiner gets one sample from each at once, and a
        # queue of one keeps only the newest until the executor takes it. tf2_ros's
        # listener keeps 100; so does this client.
        static = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        # Every transform seen, by child frame: (parent, translation, rotation x y z w, static).
        self.transforms: dict[str, tuple[str, list[float], list[float], bool]] = {}
        self.create_subscription(TFMessage, "/tf_static", self._tf_keeper(True), static)
        self.create_subscription(TFMessage, "/tf", self._tf_keeper(False), 100)
        for topic, kind in (
            ("/robot_description", String),
            ("/arm/robot_description", String),
            ("/sim_world/static_markers", MarkerArray),
            ("/sim_world/object_markers", MarkerArray),
        ):
            self.create_subscription(kind, topic, self._keeper(topic), latched)
        self.cmd = self.create_publisher(Twist, "/cmd_vel", 10)
        self.traj = self.create_publisher(JointTrajectory, "/arm_controller/joint_trajectory", 10)
        self.gripper = self.create_publisher(Float64, "/gripper/command", 10)
        self.params = self.create_client(SetParameters, "/sim_world/set_parameters")

    def _keeper(self, topic: str):
        def keep(msg) -> None:
            with self.lock:
                self.last[topic] = msg
                header = getattr(msg, "header", None)
                at = seconds(header.stamp) if header is not None else time.monotonic()
                self.arrivals.setdefault(topic, []).append(at)

        return keep

    def _tf_keeper(self, static: bool):
        def keep(msg: TFMessage) -> None:
            with self.lock:
                for t in msg.transforms:
                    v, r = t.transform.translation, t.transform.rotation
                    self.transforms[t.child_frame_id] = (
                        t.header.frame_id,
                        [v.x, v.y, v.z],
                        [r.x, r.y, r.z, r.w],
                        static,
                    )

        return keep

    def on_clock(self, msg: Clock, info) -> None:
        with self.lock:
            self.clock_samples.append((info["source_timestamp"] * 1e-9, seconds(msg.clock)))

    def on_report(self, msg: Float64, info) -> None:
        with self.lock:
            self.reports.append((info["source_timestamp"] * 1e-9, msg.data))

    def speed_over(self, window: float) -> dict:
        """Over ``window`` s: what the world reported achieving (its reports' time-weighted
        mean; each report ends the span it measured) and what /clock says of the same span
        of the world's wall clock, from the first report in the window to the last."""
        with self.lock:
            self.clock_samples, self.reports = [], []
        time.sleep(window)
        with self.lock:
            reports = list(self.reports)
        time.sleep(0.5)  # the /clock samples just after the last report, on their way
        with self.lock:
            samples = list(self.clock_samples)
        (w0, _), (w1, _) = reports[0], reports[-1]
        reported = sum(
            f * (wb - wa) for (wa, _), (wb, f) in zip(reports, reports[1:], strict=False)
        )
        # Simulation time at each end, between the /clock samples either side of it (they
        # are 0.01 s of simulation time apart): the same span the reports measured.
        begin, finish = sim_at(samples, w0), sim_at(samples, w1)
        slope = (finish - begin) / (w1 - w0)
        return {"measured": slope, "reported": reported / (w1 - w0), "span": w1 - w0}

    def on_log(self, msg: Log) -> None:
        if msg.name == "sim_world":
            with self.lock:
                self.logs.append(msg.msg)

    def get(self, topic: str) -> Any:
        with self.lock:
            return self.last.get(topic)

    def sim_time(self) -> float:
        clock = wait(lambda: self.get("/clock"), what="/clock")
        return seconds(clock.clock)

    def rate(self, topic: str, window: float) -> float:
        """Messages per second of simulation time (header stamps) over ``window`` wall s."""
        with self.lock:
            self.arrivals[topic] = []
        time.sleep(window)
        with self.lock:
            stamps = list(self.arrivals[topic])
        return (len(stamps) - 1) / (stamps[-1] - stamps[0]) if len(stamps) > 2 else 0.0

    def call(self, kind, name: str, request=None):
        client = self.create_client(kind, name)
        try:
            if not client.wait_for_service(timeout_sec=TIMEOUT):
                raise TimeoutError(f"service {name} not found")
            future = client.call_async(request or kind.Request())
            wait(future.done, what=f"{name} to answer")
            return future.result()
        finally:
            self.destroy_client(client)

    def set_param(self, name: str, value: float) -> bool:
        wait(lambda: self.params.wait_for_service(timeout_sec=0.1), what="set_parameters")
        request = SetParameters.Request()
        request.parameters = [
            Parameter(
                name=name,
                value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=value),
            )
        ]
        future = self.params.call_async(request)
        wait(future.done, what="set_parameters to answer")
        return bool(future.result().results[0].successful)

    def truth(self) -> tuple[float, float]:
        msg = self.get("/ground_truth/odom")
        return msg.pose.pose.position.x, msg.pose.pose.position.y

    def odom(self) -> tuple[float, float]:
        msg = self.get("/odom")
        return msg.pose.pose.position.x, msg.pose.pose.position.y

    def wait_sim(self, duration: float) -> None:
        """Until the simulation has run ``duration`` s. Right after a reset the last /clock
        heard may still be the old time: a clock that goes back starts the count again."""
        start = self.sim_time()

        def ran() -> bool:
            nonlocal start
            now = self.sim_time()
            start = min(start, now)
            return now - start >= duration

        wait(ran, what=f"{duration} s of simulation time")

    def log_since(self, mark: int, text: str) -> list[str]:
        with self.lock:
            return [line for line in self.logs[mark:] if text in line]


def twist(linear: float, angular: float = 0.0) -> Twist:
    msg = Twist()
    msg.linear.x, msg.angular.z = linear, angular
    return msg


def trajectory(names: list[str], points: list[tuple[list[float], float]]) -> JointTrajectory:
    msg = JointTrajectory(joint_names=names)
    for positions, at in points:
        point = JointTrajectoryPoint(positions=positions)
        point.time_from_start.sec = int(at)
        point.time_from_start.nanosec = int((at - int(at)) * 1e9)
        msg.points.append(point)
    return msg


def start(c: SimClient) -> dict:
    # Each topic is waited for: camera_info may trail the first image on a loaded machine.
    topics = ("/clock", "/scan", "/odom", "/camera/image_raw", "/camera/camera_info", "/imu")
    for topic in (*topics, "/tf", "/joint_states"):
        wait(lambda t=topic: c.get(t), what=topic)
    image, info, scan = c.get("/camera/image_raw"), c.get("/camera/camera_info"), c.get("/scan")
    wait(lambda: c.get("/real_time_factor"), what="/real_time_factor")
    joints = c.get("/joint_states")
    wait(lambda: "odom" in c.transforms and "base_link" in c.transforms, what="odom, base_link")
    mount = wait(lambda: c.transforms.get("arm_base_link"), what="world -> arm_base_link")
    return {
        "image": [image.width, image.height, image.encoding, len(image.data)],
        "info_k": list(info.k),
        "scan": [len(scan.ranges), scan.angle_min, scan.angle_increment, scan.header.frame_id],
        "joint_names": list(joints.name),
        "tf": sorted([t[0], child] for child, t in dict(c.transforms).items() if not t[3]),
        "tf_static": [mount[0], "arm_base_link", mount[1][:2], mount[3]],
        "rates": {
            "scan": c.rate("/scan", 3.0),
            "camera": c.rate("/camera/image_raw", 3.0),
        },
        "rtf": c.get("/real_time_factor").data,
    }


def chain_to_world(c: SimClient, frame: str) -> list[str]:
    """The frames from ``frame`` up to its root, as /tf and /tf_static tell them."""
    with c.lock:
        parents = {child: t[0] for child, t in c.transforms.items()}
    chain = [frame]
    while chain[-1] in parents and len(chain) < 20:
        chain.append(parents[chain[-1]])
    return chain


def matrix(translation: list[float], xyzw: list[float]) -> list[list[float]]:
    x, y, z, w = xyzw
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), translation[0]],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), translation[1]],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), translation[2]],
        [0.0, 0.0, 0.0, 1.0],
    ]


def times(a: list[list[float]], b: list[list[float]]) -> list[list[float]]:
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def frames(c: SimClient) -> dict:
    """The TF tree (robot_state_publishers included), the markers and the descriptions."""
    sensors = ("/scan", "/camera/image_raw", "/imu")
    headers = {topic: c.get(topic).header.frame_id for topic in sensors}
    wanted = ("lidar_link", "camera_optical_frame", "imu_link", "left_wheel", "tool_tip")
    for frame in wanted:
        wait(lambda f=frame: chain_to_world(c, f)[-1] == "world", what=f"{frame} -> world")
    c.call(Empty, "/pause_physics")  # odom, world -> odom and the truth of one instant
    time.sleep(0.5)
    with c.lock:
        odom, base = c.transforms["odom"], c.transforms["base_link"]
    truth = c.get("/ground_truth/odom").pose.pose
    c.call(Empty, "/unpause_physics")
    composed = times(matrix(odom[1], odom[2]), matrix(base[1], base[2]))
    static = wait(lambda: c.get("/sim_world/static_markers"), what="static markers").markers
    objects = wait(lambda: c.get("/sim_world/object_markers"), what="object markers").markers
    descriptions = {
        topic: wait(lambda t=topic: c.get(t), what=topic).data
        for topic in ("/robot_description", "/arm/robot_description")
    }
    return {
        "chains": {frame: chain_to_world(c, frame) for frame in wanted},
        "headers": headers,
        "header_frames_known": {topic: frame in c.transforms for topic, frame in headers.items()},
        "composed_vs_truth": [
            [composed[0][3], composed[1][3], composed[2][3]],
            [truth.position.x, truth.position.y, truth.position.z],
        ],
        "static_markers": [
            [
                m.action,
                m.header.frame_id,
                m.ns,
                m.type,
                [m.scale.x, m.scale.y, m.scale.z],
                [m.pose.position.x, m.pose.position.y, m.pose.position.z],
            ]
            for m in static
        ],  # fmt: skip
        "object_markers": [
            [m.ns, m.type, m.header.frame_id, [m.pose.position.x, m.pose.position.y]]
            for m in objects
        ],
        "robot_names": {
            t: re.findall(r'<robot name="([^"]*)"', d) for t, d in descriptions.items()
        },
    }


def teleop(c: SimClient) -> dict:
    """The sim_drive group's teleop: the browser's "up" key drives the robot forward."""
    keys = c.create_publisher(String, "/sim_teleop_key/_key", 10)
    wait(lambda: keys.get_subscription_count() > 0, what="the teleop's key topic")
    start_xy = c.truth()
    first = c.sim_time()
    for _ in range(20):  # a held key repeats
        keys.publish(String(data="up"))
        time.sleep(0.05)
    held = c.sim_time() - first  # simulated seconds: a busy computer holds the key longer
    c.wait_sim(1.0)  # the last command times out
    moved = (c.truth()[0] - start_xy[0], c.truth()[1] - start_xy[1])
    c.destroy_publisher(keys)
    return {"moved": moved, "held_sim_sec": held}


def sim_time(c: SimClient) -> dict:
    """A node with use_sim_time: its clock follows /clock, and stands still while paused."""
    c.set_parameters([RclpyParameter("use_sim_time", RclpyParameter.Type.BOOL, True)])
    time.sleep(1.0)
    offsets = []
    for _ in range(5):
        offsets.append(c.get_clock().now().nanoseconds * 1e-9 - c.sim_time())
        time.sleep(0.1)
    c.call(Empty, "/pause_physics")
    time.sleep(0.3)
    paused_at = c.get_clock().now().nanoseconds * 1e-9
    time.sleep(1.0)
    paused_later = c.get_clock().now().nanoseconds * 1e-9
    c.call(Empty, "/unpause_physics")
    c.set_parameters([RclpyParameter("use_sim_time", RclpyParameter.Type.BOOL, False)])
    return {"offsets": offsets, "paused": [paused_at, paused_later]}


def scan_in_room(c: SimClient) -> dict:
    c.call(Empty, "/reset_simulation")
    c.wait_sim(0.5)
    scan = c.get("/scan")
    return {
        "ranges": [float(r) for r in scan.ranges],
        "angle_min": scan.angle_min,
        "increment": scan.angle_increment,
        "truth": c.truth(),
    }


def pause_and_step(c: SimClient) -> dict:
    c.call(Empty, "/pause_physics")
    time.sleep(0.5)
    before = c.sim_time()
    time.sleep(1.0)
    still = c.sim_time()
    refused_running = None
    answer = c.call(Trigger, "/step_simulation")
    time.sleep(0.5)
    after = c.sim_time()
    c.call(Empty, "/unpause_physics")
    refused_running = c.call(Trigger, "/step_simulation")
    return {
        "before": before,
        "still": still,
        "after": after,
        "step": [answer.success, answer.message],
        "step_while_running": [refused_running.success, refused_running.message],
    }


def drive(c: SimClient) -> dict:
    """0.2 m/s for exactly 5 s of simulation time, by stepping a paused world."""
    c.call(Empty, "/reset_simulation")
    c.wait_sim(0.3)
    c.call(Empty, "/pause_physics")
    assert c.set_param("step_duration", 5.0) and c.set_param("cmd_vel_timeout", 6.0)
    time.sleep(0.3)
    truth0, odom0 = c.truth(), c.odom()
    for _ in range(5):  # the command must have arrived before the world steps
        c.cmd.publish(twist(0.2))
        time.sleep(0.1)
    answer = c.call(Trigger, "/step_simulation")
    c.cmd.publish(twist(0.0))
    time.sleep(0.5)
    truth1, odom1 = c.truth(), c.odom()
    assert c.set_param("step_duration", 0.1) and c.set_param("cmd_vel_timeout", 0.5)
    c.call(Empty, "/unpause_physics")
    return {
        "step": answer.message,
        "truth": math.dist(truth0, truth1),
        "odom": math.dist(odom0, odom1),
    }


def fast_and_timeout(c: SimClient) -> dict:
    """real_time_factor 3: simulation time runs 3x the wall clock; the command times out."""
    refused = not c.set_param("real_time_factor", -1.0)
    assert c.set_param("real_time_factor", 3.0)
    time.sleep(1.0)
    # 8 s: each end of the span is a report's publication time, off by up to 0.1 s on a
    # loaded machine; over 3 s that put /clock and the reports 8 % apart (2.39x, 2.60x).
    speed = c.speed_over(8.0)
    c.cmd.publish(twist(0.1))
    # From when the world acted on it: a loaded world took the command over a simulated
    # second late, and 1.5 s after sending it the robot still drove (0.103 m/s).
    wait(
        lambda: abs(c.get("/ground_truth/odom").twist.twist.linear.x) > 0.05,
        what="the robot to drive",
    )
    c.wait_sim(1.5)  # > cmd_vel_timeout (0.5 s): the robot has stopped
    speed_after_timeout = c.get("/ground_truth/odom").twist.twist.linear.x
    assert c.set_param("real_time_factor", 1.0)
    return {"refused_negative": refused, **speed, "speed": speed_after_timeout}


def bad_velocities(c: SimClient) -> dict:
    c.call(Empty, "/reset_simulation")
    c.wait_sim(0.3)
    mark = len(c.logs)
    t0, start_xy = c.sim_time(), c.truth()
    for _ in range(10):
        c.cmd.publish(twist(float("nan"), float("inf")))
        time.sleep(0.05)
    c.wait_sim(0.5)
    moved_after_nan = math.dist(start_xy, c.truth())
    nan_lines = c.log_since(mark, "non-finite")
    for _ in range(30):
        c.cmd.publish(twist(1e9, 0.0))
        time.sleep(0.05)
    speed = c.get("/ground_truth/odom").twist.twist.linear.x
    c.cmd.publish(twist(0.0))
    return {
        "clock_advanced": c.sim_time() - t0,
        "moved_after_nan": moved_after_nan,
        "nan_log": nan_lines[:1],
        "clamp_log": c.log_since(mark, "clamped")[:1],
        "speed_under_huge": speed,
    }


def arm(c: SimClient) -> dict:
    mark = len(c.logs)
    c.traj.publish(trajectory(["base_yaw", "shoulder", "elbow_pitch"], [([0.1, 0.2, 0.3], 1.0)]))
    c.traj.publish(trajectory(ARM, [([0.1, 0.2, 0.3], 1.0)]))
    goal = [0.5, 0.6, -0.9, -1.2]
    c.traj.publish(trajectory(ARM, [([0.25, 0.7, -1.2, -1.0], 1.0), (goal, 2.0)]))
    c.wait_sim(3.5)
    joints = c.get("/joint_states")
    reached = {n: p for n, p in zip(joints.name, joints.position, strict=True) if n in ARM}
    wait(lambda: c.log_since(mark, "rejected"), timeout=5, what="a rejection log line")
    return {
        "goal": dict(zip(ARM, goal, strict=True)),
        "reached": reached,
        "rejections": c.log_since(mark, "rejected"),
    }


def main() -> int:
    rclpy.init()
    client = SimClient()
    executor = SingleThreadedExecutor()
    executor.add_node(client)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    report: dict[str, Any] = {}
    try:
        for name, scenario in (
            ("start", start),
            ("frames", frames),
            ("teleop", teleop),
            ("sim_time", sim_time),
            ("scan_in_room", scan_in_room),
            ("pause_and_step", pause_and_step),
            ("drive", drive),
            ("fast_and_timeout", fast_and_timeout),
            ("bad_velocities", bad_velocities),
            ("arm", arm),
        ):
            try:
                report[name] = scenario(client)
            except Exception as exc:  # report it, go on with the next scenario
                report[name] = {"error": f"{type(exc).__name__}: {exc}"}
    finally:
        report["project_modules_imported"] = sorted(
            m for m in sys.modules if m.split(".")[0] in ("app", "nodes", "tests")
        )
        print(json.dumps(report), flush=True)
        executor.shutdown()
        spinner.join(5.0)
        client.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
