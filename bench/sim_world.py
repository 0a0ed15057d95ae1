"""Benchmark: the MuJoCo world's real-time factor while the dashboard draws it in a browser.

In one run, on the same machine:

1. baseline: the bare MuJoCo stepping loop (``mj_step`` on the room world, no
   sensors, no ROS) for a few seconds: simulated seconds per wall second of
   the physics alone;
2. the real dashboard (``ros2-classroom serve``) with one headless Chromium
   page on its 3D view, the 3D scene on stage, first with nothing to draw:
   the dashboard's CPU at rest;
3. ``sim_world`` and its two robot_state_publishers (the launch group
   ``sim_drive``'s, started as it starts them, without the keyboard teleop)
   as processes of their own, at ``real_time_factor`` 1, scan 10 Hz, camera
   15 Hz, while this process drives the robot in circles on ``/cmd_vel``
   (10 Hz) and the page draws it all: the room, the robots from their URDFs,
   the scan, the camera image on its frustum. Measured over the same window:
   the real-time factor the world keeps (the slope of ``/clock`` stamps
   against the wall-clock times they were published at, which DDS carries
   as each message's source timestamp, so a late delivery here does not
   count against the world; aim >= 1.0, read to two decimals), the camera's
   published rate by the same clock against its 15 Hz target (aim >= 0.9x),
   and the dashboard's CPU, whose rise over step 2 is
   ``dashboard_draw_cpu_percent``; also the page's frame rate at rest and
   while drawing (``browser_idle_fps``, ``browser_fps``: WebGL runs in
   software here, so that is where the browser's cost shows);
4. the same world at ``real_time_factor`` 0 (as fast as it can), still
   drawn: its headroom, as a ratio to the bare loop.

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

import numpy as np

from bench._common import (
    LOGS,
    configure_dds,
    launch_browser,
    open_dashboard,
    open_tool,
    rate_from_stamps,
    require_private_netns,
    rounded,
    spawn,
    start_dashboard,
)
from bench._common import stop as stop_process

CAMERA_HZ = 15.0
SCAN_HZ = 10.0
RTF_AIM = 1.0  # read to two decimals: /clock is stamped to the step, received with jitter
CAMERA_AIM = 0.9
# The launch group's members this benchmark starts (the teleop reads keys: not needed here).
MEMBERS = ("sim_world", "sim_robot_state_publisher", "sim_arm_state_publisher")
# The page has drawn the world: walls, the robot's URDF, scan points, the camera's image.
DRAWN_JS = """() => {
  const nodes = window.__viserMutable && window.__viserMutable.nodeRefFromName;
  if (!nodes) return false;
  const names = Object.keys(nodes);
  const walls = names.filter((k) => k.startsWith('/tf_view/frames/world/sim_world/')).length;
  const robot = names.some((k) => k.startsWith('/tf_view/frames/base_link/visual'));
  const scan = nodes['/laser_scan/points'];
  const camera = nodes['/tf_view/frames/camera_optical_frame/camera_view'];
  return walls >= 8 && robot && !!scan && !!camera;
}"""
# Frames the page rendered per second over ``ms`` (requestAnimationFrame).
FPS_JS = """async (ms) => {
  let frames = 0; const t0 = performance.now();
  await new Promise((done) => {
    const tick = () => { frames += 1;
      if (performance.now() - t0 < ms) requestAnimationFrame(tick); else done(); };
    requestAnimationFrame(tick);
  });
  return frames / ((performance.now() - t0) / 1000);
}"""


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


def rtf_of(clock: list[tuple[float, float]]) -> float:
    """Simulated seconds per wall second: the least-squares slope of stamps over (wall) times.

    A slope over every message, not two end points: one late publication of
    the first or last /clock would otherwise move the figure by its delay.
    """
    if len(clock) < 10:
        return math.nan
    wall = np.array([w for w, _ in clock])
    sim = np.array([s for _, s in clock])
    if wall[-1] - wall[0] <= 0:
        return math.nan
    slope, _ = np.polyfit(wall - wall[0], sim - sim[0], 1)
    return float(slope)


class Counter:
    """Publication times (the publisher's wall clock, s) and stamps (sim) of each topic."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.arrivals: dict[str, list[tuple[float, float]]] = {}

    def keep(self, topic: str, sim_time: float, published: float) -> None:
        with self.lock:
            self.arrivals.setdefault(topic, []).append((published, sim_time))

    def take(self, topic: str) -> list[tuple[float, float]]:
        with self.lock:
            return list(self.arrivals.pop(topic, []))

    def clear(self) -> None:
        with self.lock:
            self.arrivals.clear()


class CpuMeter:
    """CPU seconds (user + system) of some processes, read at the start and end of a window."""

    def __init__(self, processes: list[Any]) -> None:
        self.processes = processes
        self.start = self._total()
        self.t0 = time.monotonic()

    def _total(self) -> float:
        import psutil

        total = 0.0
        for proc in self.processes:
            try:
                times = proc.cpu_times()
                total += times.user + times.system
            except psutil.Error:  # ended meanwhile: its share is lost, not invented
                pass
        return total

    def percent(self) -> float:
        """Per cent of one core since the start."""
        return 100.0 * (self._total() - self.start) / (time.monotonic() - self.t0)


def run(seconds: float) -> dict[str, Any]:
    import psutil
    import rclpy
    from geometry_msgs.msg import Twist
    from playwright.sync_api import sync_playwright
    from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
    from rcl_interfaces.srv import SetParameters
    from rclpy.executors import SingleThreadedExecutor
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import Image, LaserScan

    from app.catalog import lookup

    errors: list[str] = []
    figures: dict[str, Any] = {"seconds": seconds}
    figures["bare_rtf"] = bare_loop(min(seconds, 5.0))

    require_private_netns("sim_world")
    configure_dds(60)
    dashboard, url = start_dashboard("bench-sim-dashboard.log")
    children: list[Any] = []
    rclpy.init()
    node = rclpy.create_node("bench_sim_world")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    counter = Counter()

    def counting(topic: str) -> Any:
        def on_message(msg: Any, info: Any) -> None:
            at = msg.clock if topic == "clock" else msg.header.stamp
            counter.keep(topic, at.sec + at.nanosec * 1e-9, info["source_timestamp"] * 1e-9)

        return on_message

    node.create_subscription(Clock, "/clock", counting("clock"), 100)
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

    timer = None
    try:
        with sync_playwright() as playwright:
            browser = launch_browser(playwright)
            page = open_dashboard(browser, url)
            open_tool(page, "3D view")
            page.get_by_label("On stage").click()
            page.get_by_role("option", name="3D scene", exact=True).click()
            dash = psutil.Process(dashboard.pid)
            time.sleep(3.0)  # the page has settled
            idle = CpuMeter([dash])
            idle_ms = int(min(seconds, 6.0) * 1000)
            figures["browser_idle_fps"] = float(page.evaluate(FPS_JS, idle_ms))
            dash_idle = figures["dashboard_idle_cpu_percent"] = idle.percent()

            for name in MEMBERS:
                entry = lookup(name)
                argv = [sys.executable, "-m", f"nodes.{entry.module}", *entry.argv_tail()]
                children.append(spawn(argv, f"bench-{name}.log")[0])
            timer = node.create_timer(0.1, drive)
            drawn = True
            try:
                page.wait_for_function(DRAWN_JS, polling=200, timeout=90_000)
            except Exception:  # not drawn: say so, and measure the rest anyway
                drawn = False
                errors.append("the page did not draw the world within 90 s")
            deadline = time.monotonic() + 30.0
            while not counter.arrivals.get("camera") and time.monotonic() < deadline:
                time.sleep(0.1)
            if not counter.arrivals.get("camera"):
                errors.append("sim_world published no camera image (see bench-sim_world.log)")
            time.sleep(2.0)  # discovery settled, the robot moving, the page drawing
            sim = psutil.Process(children[0].pid)
            counter.clear()
            meters = CpuMeter([dash]), CpuMeter([sim])
            window = time.monotonic()
            figures["browser_fps"] = float(page.evaluate(FPS_JS, int(seconds * 1000)))
            time.sleep(max(0.0, seconds - (time.monotonic() - window)))
            dash_cpu, sim_cpu = (m.percent() for m in meters)
            clock, camera, scan = (counter.take(t) for t in ("clock", "camera", "scan"))
            figures["sim_rtf"] = rtf_of(clock)
            figures["camera_rate_hz"] = rate_from_stamps([t for t, _ in camera])
            figures["scan_rate_hz"] = rate_from_stamps([t for t, _ in scan])
            figures["camera_frames"] = len(camera)
            figures["sim_camera_rate_ratio"] = figures["camera_rate_hz"] / CAMERA_HZ
            figures["sim_scan_rate_ratio"] = figures["scan_rate_hz"] / SCAN_HZ
            figures["sim_cpu_percent"] = sim_cpu
            figures["dashboard_world_cpu_percent"] = dash_cpu
            if drawn:
                figures["dashboard_draw_cpu_percent"] = dash_cpu - dash_idle
            # Headroom: as fast as it can, every sensor on, still drawn.
            if set_rtf(0.0):
                time.sleep(1.0)
                counter.clear()
                time.sleep(min(seconds, 4.0))
                figures["max_rtf"] = rtf_of(counter.take("clock"))
                figures["max_rtf_ratio_to_bare"] = figures["max_rtf"] / figures["bare_rtf"]
            else:
                errors.append("could not set real_time_factor to 0 on /sim_world")
            page.screenshot(path=str(LOGS / "bench-sim-world.png"))
            browser.close()
    finally:
        if timer is not None:
            node.destroy_timer(timer)
        executor.shutdown()
        spinner.join(2.0)
        node.destroy_node()
        rclpy.try_shutdown()
        for child in reversed(children):
            stop_process(child)
        stop_process(dashboard)
    keys = (
        "sim_rtf",
        "sim_camera_rate_ratio",
        "camera_rate_hz",
        "scan_rate_hz",
        "max_rtf",
        "dashboard_draw_cpu_percent",
        "max_rtf_ratio_to_bare",
        "sim_cpu_percent",
        "sim_scan_rate_ratio",
        "browser_fps",
    )
    for key in keys:
        value = figures.setdefault(key, math.nan)
        if isinstance(value, float) and math.isnan(value):
            errors.append(f"{key} could not be measured")
    figures["errors"] = errors
    return figures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench sim_world")
    parser.add_argument("--seconds", type=float, default=10.0)
    args = parser.parse_args(argv)
    f = run(args.seconds)
    f["aim_met"] = bool(
        round(f["sim_rtf"], 2) >= RTF_AIM and f["sim_camera_rate_ratio"] >= CAMERA_AIM
    )
    print(
        f"bare MuJoCo loop: {f['bare_rtf']:.1f}x real time; sim_world driving with scan "
        f"{SCAN_HZ:.0f} Hz and camera {CAMERA_HZ:.0f} Hz, drawn in a browser: real-time factor "
        f"{f['sim_rtf']:.3f} (aim >= {RTF_AIM}), camera {f['camera_rate_hz']:.2f} Hz = "
        f"{f['sim_camera_rate_ratio']:.2f}x its target (aim >= {CAMERA_AIM}), scan "
        f"{f['scan_rate_hz']:.2f} Hz, node CPU {f['sim_cpu_percent']:.0f} % of one core"
    )
    print(
        f"drawing the world: dashboard +{f['dashboard_draw_cpu_percent']:.0f} % of a core "
        f"(at rest {f.get('dashboard_idle_cpu_percent', math.nan):.0f} %); the page at "
        f"{f['browser_fps']:.1f} frames/s (at rest {f.get('browser_idle_fps', math.nan):.0f})"
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
