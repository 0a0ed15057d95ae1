"""Benchmark: ten turtles driven at once, pose rate at a plain subscriber and the drawn frame rate.

The dashboard (``ros2-classroom serve``) runs with one headless Chromium page
on its Turtlesim tab; turtlesim_node is started from that tab's button, as a
learner would. This process then spawns turtle2..turtle10 over ``/spawn``,
drives all ten in circles (``cmd_vel`` at 10 Hz each) and, at the same time:

- a plain rclpy subscriber (upstream's QoS: reliable, keep-last 7) counts
  every ``/turtleN/pose``: turtlesim updates every 16 ms, so the aim is
  62.5 Hz per turtle within 2 %; the rate is also computed from the
  publisher's source timestamps, which the subscriber's own scheduling
  cannot bend;
- the page counts how often the TurtleSim image really changed in the
  browser (a MutationObserver on its ``src``): the drawn frame rate, with the
  server-side cost of one frame as the panel reports it.

Run: ``.venv/bin/python tests/run.py --bench turtlesim_rate [--seconds S] [--turtles N]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import threading
import time
from typing import Any

import numpy as np

from bench._common import (
    configure_dds,
    launch_browser,
    open_dashboard,
    open_tool,
    rate_from_stamps,
    require_private_netns,
    rounded,
    start_dashboard,
    stop,
)

POSE_HZ = 62.5  # turtlesim's 16 ms update
AIM_PERCENT = 2.0

# Counts changes of the TurtleSim image's src (each is one frame the browser received).
COUNT_FRAMES_JS = """() => {
  const label = [...document.querySelectorAll('p')].find((e) => e.textContent === 'TurtleSim');
  const img = label && label.parentElement && label.parentElement.querySelector('img');
  if (!img) return false;
  window.__turtleFrames = [];
  new MutationObserver(() => window.__turtleFrames.push(performance.now()))
    .observe(img, {attributes: true, attributeFilter: ['src']});
  return true;
}"""


def cpu_percent(procs: list[Any], before: dict[int, float], seconds: float) -> float:
    """CPU (user + system) the processes used since ``before``, in % of one core."""
    busy = 0.0
    for proc in procs:
        try:
            times = proc.cpu_times()
        except Exception:  # ended meanwhile
            continue
        busy += times.user + times.system - before.get(proc.pid, 0.0)
    return 100.0 * busy / seconds


def cpu_snapshot(procs: list[Any]) -> dict[int, float]:
    out = {}
    for proc in procs:
        try:
            times = proc.cpu_times()
            out[proc.pid] = times.user + times.system
        except Exception:
            pass
    return out


class PoseCounter:
    """Arrival and source times of every pose, per turtle (the executor thread writes)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.arrivals: dict[str, list[float]] = {}
        self.sources: dict[str, list[float]] = {}
        self.recording = False

    def on_pose(self, name: str, info: Any) -> None:
        now = time.monotonic()
        with self.lock:
            if self.recording:
                self.arrivals.setdefault(name, []).append(now)
                self.sources.setdefault(name, []).append(info["source_timestamp"] * 1e-9)


def run(seconds: float, turtles: int) -> dict[str, Any]:
    import psutil
    import rclpy
    from geometry_msgs.msg import Twist
    from playwright.sync_api import sync_playwright
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from turtlesim.msg import Pose
    from turtlesim.srv import Spawn

    require_private_netns("turtlesim_rate")
    configure_dds(40)
    dashboard, url = start_dashboard("bench-turtlesim-dashboard.log")
    rclpy.init()
    node = rclpy.create_node("bench_turtlesim")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    counter = PoseCounter()
    qos = QoSProfile(depth=7, reliability=ReliabilityPolicy.RELIABLE)
    names = [f"turtle{i}" for i in range(1, turtles + 1)]
    try:
        with sync_playwright() as pw:
            browser = launch_browser(pw)
            page = open_dashboard(browser, url)
            open_tool(page, "Turtlesim")
            page.get_by_role("button", name="Start turtlesim_node", exact=True).click()
            spawn = node.create_client(Spawn, "/spawn")
            if not spawn.wait_for_service(timeout_sec=60):
                raise SystemExit("turtlesim's /spawn never appeared")
            for i, name in enumerate(names[1:], start=1):
                # Circles of 1 m radius that stay clear of the walls: a wall hit logs a
                # warning at every update, which would measure logging, not the sim.
                request = Spawn.Request(x=1.5 + (i % 5) * 2.0, y=1.5 + (i // 5) * 5.0, name=name)
                future = spawn.call_async(request)
                deadline = time.monotonic() + 20
                while not future.done() and time.monotonic() < deadline:
                    time.sleep(0.01)
                if not future.done() or future.result().name != name:
                    raise SystemExit(f"could not spawn {name}")
            for name in names:
                node.create_subscription(
                    Pose,
                    f"/{name}/pose",
                    lambda _msg, info, name=name: counter.on_pose(name, info),
                    qos,
                )
            drivers = [node.create_publisher(Twist, f"/{name}/cmd_vel", qos) for name in names]
            page.wait_for_function(COUNT_FRAMES_JS, polling=200, timeout=30_000)

            def drive() -> None:
                for publisher in drivers:
                    twist = Twist()
                    twist.linear.x, twist.angular.z = 1.0, 1.0
                    publisher.publish(twist)

            timer = node.create_timer(0.1, drive)
            time.sleep(3.0)  # discovery, the first turns, the view catching up
            page.evaluate("() => { window.__turtleFrames = []; }")
            me = psutil.Process()
            dash = psutil.Process(dashboard.pid)
            sims = [
                c
                for c in dash.children(recursive=True)
                if "turtlesim_node" in " ".join(c.cmdline())
            ]
            browsers = [c for c in me.children(recursive=True) if "chrom" in c.name()]
            groups = {"dashboard": [dash], "turtlesim": sims, "browser": browsers, "bench": [me]}
            before = {k: cpu_snapshot(v) for k, v in groups.items()}
            with counter.lock:
                counter.recording = True
            t0 = time.monotonic()
            time.sleep(seconds)
            with counter.lock:
                counter.recording = False
            spent = time.monotonic() - t0
            cpu = {k: cpu_percent(v, before[k], spent) for k, v in groups.items()}
            frames = page.evaluate("() => window.__turtleFrames")
            status = page.get_by_text(re.compile(r"Drawing .*frames drawn")).first.inner_text()
            node.destroy_timer(timer)
            browser.close()
    finally:
        executor.shutdown()
        spinner.join(2.0)
        node.destroy_node()
        rclpy.try_shutdown()
        stop(dashboard)
    arrival = {n: rate_from_stamps(counter.arrivals.get(n, [])) for n in names}
    source = {n: rate_from_stamps(counter.sources.get(n, [])) for n in names}

    def worst_error(rates: dict[str, float]) -> float:
        values = [r for r in rates.values() if not math.isnan(r)]
        if len(values) < len(rates):
            return math.nan  # a turtle never reported: no figure
        return max(100.0 * abs(r - POSE_HZ) / POSE_HZ for r in values)

    cost = re.search(r"([\d.]+) ms a frame", status)
    sent = re.search(r"(\d+) frames/s", status)
    drawn = rate_from_stamps([t / 1000.0 for t in frames])
    return {
        "seconds": seconds,
        "turtles": turtles,
        "pose_rate_min_hz": min(arrival.values()),
        "pose_rate_max_hz": max(arrival.values()),
        "pose_rate_error_percent": worst_error(arrival),
        "pose_source_rate_error_percent": worst_error(source),
        "poses_received": sum(len(v) for v in counter.arrivals.values()),
        # The longest silence of any turtle's pose, by the sim's own clock.
        "pose_max_gap_ms": 1000.0
        * max((max(np.diff(v)) for v in counter.sources.values() if len(v) > 1), default=math.nan),
        "browser_frames_per_s": drawn,
        "server_frame_ms": float(cost.group(1)) if cost else math.nan,
        "server_frames_per_s": float(sent.group(1)) if sent else math.nan,
        **{f"cpu_{k}_percent": v for k, v in cpu.items()},
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench turtlesim_rate")
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--turtles", type=int, default=10)
    args = parser.parse_args(argv)
    f = run(args.seconds, args.turtles)
    f["aim_met"] = bool(f["pose_rate_error_percent"] <= AIM_PERCENT)
    print(
        f"{f['turtles']} turtles driven for {f['seconds']:.0f} s: pose rate at a plain "
        f"subscriber {f['pose_rate_min_hz']:.2f}-{f['pose_rate_max_hz']:.2f} Hz, worst "
        f"{f['pose_rate_error_percent']:.2f} % off 62.5 (aim <= {AIM_PERCENT:.0f} %; from "
        f"source stamps {f['pose_source_rate_error_percent']:.2f} %; longest gap "
        f"{f['pose_max_gap_ms']:.0f} ms)"
    )
    print(
        f"browser: {f['browser_frames_per_s']:.1f} frames/s drawn; server: "
        f"{f['server_frames_per_s']:.0f} frames/s sent, {f['server_frame_ms']:.1f} ms a frame"
    )
    print(
        "CPU, % of one core: "
        + ", ".join(
            f"{k} {f[f'cpu_{k}_percent']:.0f}"
            for k in ("turtlesim", "dashboard", "browser", "bench")
        )
    )
    print(json.dumps(rounded(f, 3), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
