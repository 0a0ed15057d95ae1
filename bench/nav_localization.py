"""Benchmark: how well amcl localizes the robot on the office map while it drives the tour.

In one run, on the same machine: sim_world with the office world
(``publish_world_tf:=false``, camera off, ``real_time_factor`` 2 by default),
its robot_state_publisher, Nav2's map_server with the shipped office map
(``map_server_office``) and amcl (``amcl``, its debug log on), each a process
of its own; both Nav2 servers are configured and activated through their
``change_state`` services, as the lifecycle manager does. This process sends
the start pose on /initialpose (rviz's "2D Pose Estimate": the true pose, 0.25
m and 15 degrees standard deviation), waits for /amcl_pose, then drives the
office tour (``nodes.office_tour``: 19 waypoints, about 38 m, a go-to-point
controller on /ground_truth/odom) and compares every /amcl_pose stamped during
the tour with the ground truth at the same (simulated) time. The map frame is
the world frame (the map was drawn from the world file).

- ``amcl_error_m`` / ``amcl_error_p95_m``: mean and 95th percentile of the
  position error (aim: mean <= 0.10 m; issue 40 asks 0.10 m at p95);
- ``amcl_heading_error_deg`` / ``amcl_heading_error_p95_deg`` (issue 40: <= 5
  degrees at p95), ``amcl_error_max_m``, ``amcl_poses`` (how many);
- ``amcl_update_ms_p50`` / ``_p95``: the node's own time for one filter update
  (motion, sensor, resampling, estimate, /amcl_pose, /particle_cloud and the
  transform), read from its debug line ``filter update: X ms (Y ms CPU)``;
  ``amcl_update_cpu_ms_p50`` / ``_p95`` the CPU time of the same (the wall
  time also counts the waits for a core when others share the machine);
- ``amcl_cpu_percent``: the amcl process's CPU over the tour (per cent of one
  core), and ``amcl_particles_last``, ``tour_sim_sec``, ``rtf_kept``.

``--global-tries N`` (default 0) then measures global localization: N times,
``reinitialize_global_localization`` where the robot is, then the tour driven
on leg by leg from there; a try converged if within ``--global-seconds``
(simulated) /amcl_pose came within 0.25 m and 10 degrees of the truth and
stayed there for 3 updates in a row: ``global_converged_percent``.

``--record FILE.npz`` also keeps what amcl was given and what it answered
(the scans, odom -> base_link, the ground truth, /amcl_pose) for replaying
the filter in-process.

A figure that cannot be measured is NaN (``null`` in the JSON) with the
reason printed as a ``FAILED:`` line, and the benchmark exits 1.

Run: ``.venv/bin/python tests/run.py --bench nav_localization [--rtf R]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import bisect
import json
import math
import os
import re
import threading
import time
from typing import Any

from bench._common import configure_dds, percentile, require_private_netns, rounded
from nodes.office_tour import REACHED, TOUR, command  # the tour office_tour drives

AIM_MEAN_M = 0.10
AIM_P95_M = 0.10
AIM_P95_DEG = 5.0
AIM_UPDATE_MS = 30.0  # one update with its /particle_cloud, 2000 particles
INITIAL_STD = (0.25, math.radians(15.0))  # m, rad: rviz's 2D Pose Estimate
CONVERGED = (0.25, math.radians(10.0))  # m, rad: a global localization that found the robot
UPDATE_LINE = re.compile(r"filter update: ([0-9.]+) ms \(([0-9.]+) ms CPU\) with (\d+) particles")


def angle(a: float) -> float:
    return math.atan2(math.sin(a), math.cos(a))


def yaw_of(q: Any) -> float:
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


class Truth:
    """Ground-truth poses by simulated time, interpolated at any stamp they cover."""

    def __init__(self) -> None:
        self.times: list[float] = []
        self.poses: list[tuple[float, float, float]] = []

    def add(self, t: float, pose: tuple[float, float, float]) -> None:
        if self.times and t <= self.times[-1]:
            if t < self.times[-1] - 1.0:  # the world was reset: start again
                self.times, self.poses = [], []
            else:
                return
        self.times.append(t)
        self.poses.append(pose)

    def at(self, t: float) -> tuple[float, float, float] | None:
        k = bisect.bisect_left(self.times, t)
        if k == 0 or k >= len(self.times):
            return None
        t0, t1 = self.times[k - 1], self.times[k]
        if t1 - t0 > 0.5:
            return None
        a, b = self.poses[k - 1], self.poses[k]
        f = (t - t0) / (t1 - t0) if t1 > t0 else 0.0
        return (
            a[0] + f * (b[0] - a[0]),
            a[1] + f * (b[1] - a[1]),
            a[2] + f * angle(b[2] - a[2]),
        )


def errors_between(
    estimates: list[tuple[float, float, float, float]], truth: Truth, t0: float, t1: float
) -> tuple[list[float], list[float]]:
    """Position (m) and heading (rad) errors of the estimates stamped in [t0, t1]."""
    d, a = [], []
    for t, x, y, yaw in estimates:
        if not t0 <= t <= t1:
            continue
        true = truth.at(t)
        if true is None:
            continue
        d.append(math.hypot(x - true[0], y - true[1]))
        a.append(abs(angle(yaw - true[2])))
    return d, a


def run(
    rtf: float, global_tries: int, global_seconds: float, record: str | None = None
) -> dict[str, Any]:
    import psutil
    import rclpy
    from geometry_msgs.msg import PoseWithCovarianceStamped, Twist
    from lifecycle_msgs.msg import Transition
    from lifecycle_msgs.srv import ChangeState
    from nav_msgs.msg import Odometry
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
    from sensor_msgs.msg import LaserScan
    from std_srvs.srv import Empty
    from tf2_msgs.msg import TFMessage

    from app.catalog import lookup
    from app.supervisor import Supervisor

    require_private_netns("nav_localization")
    configure_dds(71)
    figures: dict[str, Any] = {"rtf_asked": rtf, "waypoints": len(TOUR), "errors": []}
    figures["load_average"] = os.getloadavg()[0]  # others on the cores stretch wall times
    supervisor = Supervisor(dict(os.environ), max_log_lines=200_000)
    rclpy.init()
    node = rclpy.create_node("bench_nav_localization")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    lock = threading.Lock()
    truth = Truth()
    latest: dict[str, Any] = {"truth": None}
    estimates: list[tuple[float, float, float, float]] = []  # stamp, x, y, yaw

    def on_truth(msg: Odometry) -> None:
        p = msg.pose.pose
        t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        pose = (p.position.x, p.position.y, yaw_of(p.orientation))
        with lock:
            truth.add(t, pose)
            latest["truth"] = (t, *pose)
            if record:
                recorded["truth"].append((t, *pose))

    def on_pose(msg: PoseWithCovarianceStamped) -> None:
        p = msg.pose.pose
        t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        with lock:
            estimates.append((t, p.position.x, p.position.y, yaw_of(p.orientation)))

    recorded: dict[str, list] = {"scans": [], "odom": [], "truth": []}
    scan_info: dict[str, float] = {}

    def on_scan(msg: LaserScan) -> None:
        t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        scan_info.update(
            angle_min=msg.angle_min,
            angle_increment=msg.angle_increment,
            range_min=msg.range_min,
            range_max=msg.range_max,
        )
        with lock:
            recorded["scans"].append((t, list(msg.ranges)))

    def on_tf(msg: TFMessage) -> None:
        for tf in msg.transforms:
            if tf.header.frame_id == "odom" and tf.child_frame_id == "base_link":
                t = tf.header.stamp.sec + tf.header.stamp.nanosec * 1e-9
                tr = tf.transform
                with lock:
                    recorded["odom"].append(
                        (t, tr.translation.x, tr.translation.y, yaw_of(tr.rotation))
                    )

    if record:
        node.create_subscription(LaserScan, "/scan", on_scan, qos_profile_sensor_data)
        node.create_subscription(TFMessage, "/tf", on_tf, 100)

    latched = QoSProfile(
        depth=1,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    node.create_subscription(Odometry, "/ground_truth/odom", on_truth, 50)
    node.create_subscription(PoseWithCovarianceStamped, "/amcl_pose", on_pose, latched)
    cmd = node.create_publisher(Twist, "/cmd_vel", 10)
    initial = node.create_publisher(PoseWithCovarianceStamped, "/initialpose", 10)

    def call(srv_type: Any, name: str, request: Any, timeout: float = 30.0) -> Any:
        client = node.create_client(srv_type, name)
        try:
            if not client.wait_for_service(timeout_sec=timeout):
                raise RuntimeError(f"no service {name} within {timeout:.0f} s")
            done = threading.Event()
            future = client.call_async(request)
            future.add_done_callback(lambda _f: done.set())
            if not done.wait(timeout):
                raise RuntimeError(f"{name} did not answer within {timeout:.0f} s")
            return future.result()
        finally:
            node.destroy_client(client)

    def now_truth() -> tuple[float, float, float, float]:
        with lock:
            return latest["truth"]

    def drive_to(goal: tuple[float, float], deadline_s: float = 120.0) -> None:
        leg_deadline = time.monotonic() + deadline_s
        while True:
            _t, x, y, yaw = now_truth()
            if math.dist((x, y), goal) < REACHED:
                return
            if time.monotonic() > leg_deadline:
                raise RuntimeError(f"waypoint {goal} not reached (robot at {x:.2f}, {y:.2f})")
            linear, angular = command((x, y, yaw), goal)
            twist = Twist()
            twist.linear.x, twist.angular.z = linear, angular
            cmd.publish(twist)
            time.sleep(0.05)

    try:
        sim_args = ("-p", "camera_rate:=0.0", "-p", f"real_time_factor:={rtf}")
        supervisor.start_program(lookup("sim_office_mapping"), sim_args)
        supervisor.start("sim_robot_state_publisher")
        supervisor.start("map_server_office")
        supervisor.start("amcl", ("--log-level", "amcl:=debug"))
        for server in ("/map_server", "/amcl"):
            for transition in (Transition.TRANSITION_CONFIGURE, Transition.TRANSITION_ACTIVATE):
                request = ChangeState.Request(transition=Transition(id=transition))
                if not call(ChangeState, f"{server}/change_state", request, 60.0).success:
                    raise RuntimeError(f"{server} refused transition {transition}")
        deadline = time.monotonic() + 90.0
        while now_truth() is None:
            if time.monotonic() > deadline:
                raise RuntimeError("no /ground_truth/odom within 90 s")
            time.sleep(0.1)

        # The start pose on /initialpose until amcl answers with /amcl_pose.
        _t, x0, y0, yaw0 = now_truth()
        msg = PoseWithCovarianceStamped()
        msg.header.frame_id = "map"
        msg.pose.pose.position.x, msg.pose.pose.position.y = x0, y0
        msg.pose.pose.orientation.z = math.sin(yaw0 / 2.0)
        msg.pose.pose.orientation.w = math.cos(yaw0 / 2.0)
        covariance = [0.0] * 36
        covariance[0] = covariance[7] = INITIAL_STD[0] ** 2
        covariance[35] = INITIAL_STD[1] ** 2
        msg.pose.covariance = covariance
        deadline = time.monotonic() + 60.0
        while True:
            with lock:
                answered = bool(estimates)
            if answered:
                break
            if time.monotonic() > deadline:
                raise RuntimeError("no /amcl_pose within 60 s of the initial pose")
            initial.publish(msg)
            time.sleep(1.0)
        with lock:
            figures["amcl_start_error_m"] = math.hypot(estimates[-1][1] - x0, estimates[-1][2] - y0)

        amcl = psutil.Process(supervisor.status("amcl").pid)
        cpu0 = sum(amcl.cpu_times()[:2])
        sim0, wall0 = now_truth()[0], time.monotonic()
        for goal in TOUR:
            drive_to(goal)
        cmd.publish(Twist())
        wall = time.monotonic() - wall0
        figures["amcl_cpu_percent"] = 100.0 * (sum(amcl.cpu_times()[:2]) - cpu0) / wall
        sim1 = now_truth()[0]
        figures["tour_sim_sec"] = sim1 - sim0
        figures["tour_wall_sec"] = wall
        figures["rtf_kept"] = (sim1 - sim0) / wall
        time.sleep(1.0)  # the last updates' /amcl_pose
        with lock:
            d, a = errors_between(list(estimates), truth, sim0, sim1)
        figures["amcl_poses"] = len(d)
        if len(d) < 20:
            raise RuntimeError(f"only {len(d)} /amcl_pose matched to the ground truth on the tour")
        figures["amcl_error_m"] = sum(d) / len(d)
        figures["amcl_error_p95_m"] = percentile(d, 95)
        figures["amcl_error_max_m"] = max(d)
        figures["amcl_heading_error_deg"] = math.degrees(sum(a) / len(a))
        figures["amcl_heading_error_p95_deg"] = math.degrees(percentile(a, 95))
        updates = [UPDATE_LINE.search(line) for line in supervisor.output("amcl")]
        times = [float(m.group(1)) for m in updates if m]
        if not times:
            raise RuntimeError("no 'filter update' debug lines from amcl")
        figures["amcl_updates"] = len(times)
        figures["amcl_update_ms_p50"] = percentile(times, 50)
        figures["amcl_update_ms_p95"] = percentile(times, 95)
        cpu = [float(m.group(2)) for m in updates if m]
        figures["amcl_update_cpu_ms_p50"] = percentile(cpu, 50)
        figures["amcl_update_cpu_ms_p95"] = percentile(cpu, 95)
        figures["amcl_particles_last"] = int([m for m in updates if m][-1].group(3))
        if record:
            import numpy as np

            arrays: dict[str, Any] = {k: np.array(v) for k, v in scan_info.items()}
            with lock:
                arrays.update(
                    scan_stamps=np.array([t for t, _ in recorded["scans"]]),
                    scan_ranges=np.array([r for _, r in recorded["scans"]], np.float32),
                    odom=np.array(recorded["odom"]),
                    truth=np.array(recorded["truth"]),
                    amcl_pose=np.array(estimates),
                    tour=np.array([sim0, sim1]),
                    update_ms=np.array(times),
                )
            np.savez_compressed(record, **arrays)

        # Global localization: lost on purpose, then driven on.
        if global_tries:
            results: list[float] = []  # simulated seconds to converge, inf if it did not
            leg = 0  # the tour goes on from its end (0, 0), which is where it starts
            for k in range(global_tries):
                with lock:
                    since = len(estimates)
                call(Empty, "/reinitialize_global_localization", Empty.Request())
                t_start = now_truth()[0]
                converged_at = math.inf
                while now_truth()[0] - t_start < global_seconds:
                    drive_to(TOUR[leg % len(TOUR)])
                    leg += 1
                    with lock:
                        fresh = estimates[since:]
                    run_length = 0
                    for t, x, y, yaw in fresh:
                        true = truth.at(t)
                        if true is None:
                            continue
                        ok = math.hypot(x - true[0], y - true[1]) < CONVERGED[0] and (
                            abs(angle(yaw - true[2])) < CONVERGED[1]
                        )
                        run_length = run_length + 1 if ok else 0
                        if run_length == 3:
                            if t - t_start <= global_seconds:  # legs may end after the window
                                converged_at = t - t_start
                            break
                    if math.isfinite(converged_at):
                        break
                cmd.publish(Twist())
                results.append(converged_at)
                print(
                    f"  global try {k + 1}: "
                    + (
                        f"converged after {converged_at:.1f} s"
                        if math.isfinite(converged_at)
                        else f"not converged within {global_seconds:g} s"
                    ),
                    flush=True,
                )
            good = [r for r in results if math.isfinite(r)]
            figures["global_tries"] = len(results)
            figures["global_converged_percent"] = 100.0 * len(good) / len(results)
            figures["global_converge_sec_p50"] = percentile(good, 50)
    except Exception as exc:  # reported, never quiet
        figures["errors"].append(str(exc))
    finally:
        try:
            cmd.publish(Twist())
        except Exception:
            pass
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
        supervisor.shutdown()
    for key in (
        "amcl_error_m",
        "amcl_error_p95_m",
        "amcl_heading_error_deg",
        "amcl_heading_error_p95_deg",
        "amcl_update_ms_p50",
        "amcl_update_ms_p95",
        "amcl_update_cpu_ms_p50",
        "amcl_update_cpu_ms_p95",
        "amcl_cpu_percent",
        "tour_sim_sec",
    ):
        figures.setdefault(key, math.nan)
    return figures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench nav_localization")
    parser.add_argument("--rtf", type=float, default=2.0, help="the world's real_time_factor")
    parser.add_argument(
        "--global-tries", type=int, default=0, help="global localization tries after the tour"
    )
    parser.add_argument(
        "--global-seconds", type=float, default=60.0, help="simulated s a global try may take"
    )
    parser.add_argument("--record", help="keep the inputs and answers in this .npz file")
    args = parser.parse_args(argv)
    f = run(args.rtf, args.global_tries, args.global_seconds, args.record)
    f["aim_met"] = bool(
        f["amcl_error_m"] <= AIM_MEAN_M
        and f["amcl_error_p95_m"] <= AIM_P95_M
        and f["amcl_heading_error_p95_deg"] <= AIM_P95_DEG
    )
    print(
        f"amcl on a {f['tour_sim_sec']:.0f} s (simulated) tour of the office: position error "
        f"mean {f['amcl_error_m']:.3f} m (aim <= {AIM_MEAN_M:g}), p95 "
        f"{f['amcl_error_p95_m']:.3f} m (issue 40: <= {AIM_P95_M:g}); heading mean "
        f"{f['amcl_heading_error_deg']:.1f} deg, p95 {f['amcl_heading_error_p95_deg']:.1f} deg "
        f"(issue 40: <= {AIM_P95_DEG:g})"
    )
    print(
        f"  one filter update (with its /particle_cloud; the node's debug lines, "
        f"{f.get('amcl_updates', 0)} updates): wall p50 {f['amcl_update_ms_p50']:.1f} ms, p95 "
        f"{f['amcl_update_ms_p95']:.1f} ms; CPU p50 {f['amcl_update_cpu_ms_p50']:.1f} ms, p95 "
        f"{f['amcl_update_cpu_ms_p95']:.1f} ms (aim <= {AIM_UPDATE_MS:g})"
    )
    print(
        f"  amcl {f['amcl_cpu_percent']:.0f} % of a core over the tour; world at "
        f"{f.get('rtf_kept', math.nan):.2f}x real time (asked {f['rtf_asked']:g}); "
        f"1-minute load average at the start {f.get('load_average', math.nan):.1f}"
    )
    if "global_converged_percent" in f:
        print(
            f"  global localization: converged in {f['global_converged_percent']:.0f} % of "
            f"{f['global_tries']} tries within {args.global_seconds:g} s (simulated), p50 "
            f"{f['global_converge_sec_p50']:.1f} s"
        )
    for error in f["errors"]:
        print(f"FAILED: not measured: {error}")
    print(json.dumps(rounded(f, 3), sort_keys=True))
    return 1 if f["errors"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
