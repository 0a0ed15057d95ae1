"""Benchmark: the MuJoCo world's real-time factor with the robot driving, beside bare MuJoCo.

In one run, on the same machine:

1. baseline: the bare MuJoCo stepping loop (``mj_step`` on the room world, no
   sensors, no ROS) for a few seconds: how many simulated seconds per wall
   second the physics alone can do;
2. ``python -m nodes.sim_world`` as its own process at ``real_time_factor`` 1,
   its scan at 10 Hz and camera at 15 Hz, while this process drives the robot
   in circles on ``/cmd_vel`` (10 Hz) and counts ``/clock``, ``/scan`` and
   ``/camera/image_raw``: the real-time factor it keeps (aim >= 1.0; read from
   ``/clock`` against the wall clock) and the camera's published rate against
   its 15 Hz target (aim >= 0.9x), plus the node's CPU;
3. the same node at ``real_time_factor`` 0 (as fast as it can) with every
   sensor on: its headroom, as a ratio to the bare loop;
4. the dashboard's extra CPU for drawing the world: not measurable until the
   3D view draws it, so reported as not measured.

A figure that cannot be measured is NaN (``null`` in the JSON) with the reason
in ``errors``, printed as a ``FAILED:`` line, and the benchmark exits 1: never
missing, never quiet.

Run: ``.venv/bin/python tests/run.py --bench sim_world [--seconds S]``.
The last line printed is one JSON object (keys ``sim_rtf``, ``sim_camera_rate_ratio``, ...).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import threading
import time
from typing import Any

from bench._common import configure_dds, rate_from_stamps, require_private_netns, rounded, spawn
from bench._common import stop as stop_process

CAMERA_HZ = 15.0
SCAN_HZ = 10.0


def bare_loop(seconds: float) -> float:
    """Simulated seconds per wall second of the bare mj_step loop on the room world."""
    import mujoco

    from nodes.common.sim.assets import load_world

    model = load_world("room")
    data = mujoco.MjData(model)
    steps = 0
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        mujoco.mj_step(model, data, 200)
        steps += 200
    return steps * model.opt.timestep / (time.perf_counter() - t0)


class Counter:
    """Arrival times (wall) and stamps (sim) of each topic; the executor thread writes."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.arrivals: dict[str, list[tuple[float, float]]] = {}

    def keep(self, topic: str, sim_time: float) -> None:
        with self.lock:
            self.arrivals.setdefault(topic, []).append((time.monotonic(), sim_time))

    def take(self, topic: str) -> list[tuple[float, float]]:
        with self.lock:
            return list(self.arrivals.pop(topic, []))

    def clear(self) -> None:
        with self.lock:
            self.arrivals.clear()


def run(seconds: float) -> dict[str, Any]:
    import psutil
    import rclpy
    from geometry_msgs.msg import Twist
    from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
    from rcl_interfaces.srv import SetParameters
    from rclpy.executors import SingleThreadedExecutor
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import Image, LaserScan

    errors: list[str] = []
    figures: dict[str, Any] = {"seconds": seconds}
    figures["bare_rtf"] = bare_loop(min(seconds, 5.0))

    require_private_netns("sim_world")
    configure_dds(60)
    proc, log = spawn([sys.executable, "-m", "nodes.sim_world"], "bench-sim-world.log")
    rclpy.init()
    node = rclpy.create_node("bench_sim_world")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    counter = Counter()

    def counting(topic: str) -> Any:
        def on_message(msg: Any) -> None:
            at = msg.clock if topic == "clock" else msg.header.stamp
            counter.keep(topic, at.sec + at.nanosec * 1e-9)

        return on_message

    node.create_subscription(Clock, "/clock", counting("clock"), 10)
    node.create_subscription(Image, "/camera/image_raw", counting("camera"), 5)
    node.create_subscription(LaserScan, "/scan", counting("scan"), 10)
    cmd = node.create_publisher(Twist, "/cmd_vel", 10)
    params = node.create_client(SetParameters, "/sim_world/set_parameters")

    def drive() -> None:
        twist = Twist()
        twist.linear.x, twist.angular.z = 0.2, 0.4  # circles of 0.5 m radius, clear of walls
        cmd.publish(twist)

    def set_rtf(value: float) -> bool:
        if not params.wait_for_service(timeout_sec=20.0):
            return False
        request = SetParameters.Request()
        value_msg = ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=value)
        request.parameters = [Parameter(name="real_time_factor", value=value_msg)]
        future = params.call_async(request)
        deadline = time.monotonic() + 10.0
        while not future.done() and time.monotonic() < deadline:
            time.sleep(0.01)
        return bool(future.done() and future.result().results[0].successful)

    def rtf_of(clock: list[tuple[float, float]]) -> float:
        if len(clock) < 2 or clock[-1][0] <= clock[0][0]:
            return math.nan
        return (clock[-1][1] - clock[0][1]) / (clock[-1][0] - clock[0][0])

    timer = node.create_timer(0.1, drive)
    try:
        deadline = time.monotonic() + 60.0
        while not counter.arrivals.get("camera") and time.monotonic() < deadline:
            if proc.poll() is not None:
                break
            time.sleep(0.1)
        if not counter.arrivals.get("camera"):
            errors.append(f"sim_world published no camera image in 60 s (see {log})")
        else:
            time.sleep(2.0)  # discovery settled, the robot moving
            sim_proc = psutil.Process(proc.pid)
            cpu0 = sum(sim_proc.cpu_times()[:2])
            counter.clear()
            t0 = time.monotonic()
            time.sleep(seconds)
            spent = time.monotonic() - t0
            figures["sim_cpu_percent"] = 100.0 * (sum(sim_proc.cpu_times()[:2]) - cpu0) / spent
            clock, camera, scan = (
                counter.take("clock"),
                counter.take("camera"),
                counter.take("scan"),
            )
            figures["sim_rtf"] = rtf_of(clock)
            figures["camera_rate_hz"] = rate_from_stamps([t for t, _ in camera])
            figures["scan_rate_hz"] = rate_from_stamps([t for t, _ in scan])
            figures["camera_frames"] = len(camera)
            figures["sim_camera_rate_ratio"] = figures["camera_rate_hz"] / CAMERA_HZ
            figures["sim_scan_rate_ratio"] = figures["scan_rate_hz"] / SCAN_HZ
            # Headroom: as fast as it can, every sensor on.
            if set_rtf(0.0):
                time.sleep(1.0)
                counter.clear()
                time.sleep(min(seconds, 4.0))
                figures["max_rtf"] = rtf_of(counter.take("clock"))
                figures["max_rtf_ratio_to_bare"] = figures["max_rtf"] / figures["bare_rtf"]
            else:
                errors.append("could not set real_time_factor to 0 on /sim_world")
    finally:
        executor.shutdown()
        node.destroy_timer(timer)
        spinner.join(2.0)
        node.destroy_node()
        rclpy.try_shutdown()
        stop_process(proc)
    for key in ("sim_rtf", "sim_camera_rate_ratio", "camera_rate_hz", "scan_rate_hz", "max_rtf"):
        value = figures.setdefault(key, math.nan)
        if isinstance(value, float) and math.isnan(value) and not errors:
            errors.append(f"{key} could not be measured")
    # The third figure needs the 3D view to draw this world, which it does not yet.
    figures["dashboard_draw_cpu_percent"] = math.nan
    errors.append(
        "dashboard_draw_cpu_percent: the dashboard's 3D view does not draw the MuJoCo world yet"
    )
    figures.setdefault("max_rtf_ratio_to_bare", math.nan)
    figures.setdefault("sim_cpu_percent", math.nan)
    figures.setdefault("sim_scan_rate_ratio", math.nan)
    figures["errors"] = errors
    return figures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench sim_world")
    parser.add_argument("--seconds", type=float, default=10.0)
    args = parser.parse_args(argv)
    f = run(args.seconds)
    f["aim_met"] = bool(f["sim_rtf"] >= 1.0 * 0.98 and f["sim_camera_rate_ratio"] >= 0.9)
    print(
        f"bare MuJoCo loop: {f['bare_rtf']:.1f}x real time; sim_world driving with scan "
        f"{SCAN_HZ:.0f} Hz and camera {CAMERA_HZ:.0f} Hz: real-time factor {f['sim_rtf']:.3f} "
        f"(aim >= 1.0), camera {f['camera_rate_hz']:.2f} Hz = {f['sim_camera_rate_ratio']:.2f}x "
        f"its target (aim >= 0.9), scan {f['scan_rate_hz']:.2f} Hz, node CPU "
        f"{f['sim_cpu_percent']:.0f} % of one core"
    )
    print(
        f"as fast as it can, every sensor on: {f['max_rtf']:.1f}x real time = "
        f"{f['max_rtf_ratio_to_bare']:.2f} of the bare loop"
    )
    for error in f["errors"]:
        print(f"FAILED: not measured: {error}")  # summary.py shows it as the row's reason
    print(json.dumps(rounded(f, 3), sort_keys=True))
    return 1 if f["errors"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
