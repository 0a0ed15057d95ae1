"""Benchmark: the stage's live graph with 30 nodes and 60 topics, beside the same page
with the stage off.

A load process holds 30 rclpy nodes; node i publishes two topics and
subscribes to the two of node i+1, so 60 topics each have a publisher and a
subscriber. One topic runs at 1 kHz, the rest at 1-10 Hz. The real dashboard
(``ros2-classroom serve``) and one headless Chromium page (1366x768) watch it:

- **graph**: the stage shows the live graph (90 boxes, message dots moving);
- **off**: the same page with the stage on "3D scene" (no graph drawn or
  measured), the baseline, in the same run, under the same load.

Phases alternate (on, off, off, on, ...); in each the page counts its own
frames (requestAnimationFrame) and psutil samples the dashboard's CPU over
the same seconds. ``stage_graph_fps`` is the frame rate with the graph on
(aim > 30); ``stage_extra_cpu_percent`` the dashboard's CPU with the graph
on minus with it off (% of one core, aim < 5).
Run: ``.venv/bin/python tests/run.py --bench stage_graph [--seconds S]
[--rounds N]``. The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from typing import Any

from bench._common import (
    configure_dds,
    launch_browser,
    require_private_netns,
    rounded,
    sample,
    spawn,
    start_dashboard,
    stop,
    wait_for_text,
)

NODES = 30
FAST_HZ = 1000.0

LOAD = f"""
import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import String

NODES, FAST_HZ = {NODES}, {FAST_HZ}
rclpy.init()
executor = SingleThreadedExecutor()
nodes = []
for i in range(NODES):
    node = Node(f"stage_load_{{i:02d}}")
    for j in range(2):
        topic = f"/stage_topic_{{i:02d}}_{{j}}"
        hz = FAST_HZ if (i, j) == (0, 0) else 1.0 + (2 * i + j) % 10
        pub = node.create_publisher(String, topic, 10)
        msg = String(data=topic)
        node.create_timer(1.0 / hz, lambda pub=pub, msg=msg: pub.publish(msg))
        source = f"/stage_topic_{{(i + 1) % NODES:02d}}_{{j}}"
        node.create_subscription(String, source, lambda _m: None, 10)
    executor.add_node(node)
    nodes.append(node)
print("STAGE LOAD READY", flush=True)
try:
    executor.spin()
except (KeyboardInterrupt, ExternalShutdownException):
    pass
finally:
    rclpy.try_shutdown()
"""

FPS_JS = """async (ms) => {
  let frames = 0;
  const t0 = performance.now();
  await new Promise((done) => {
    const tick = () => {
      frames += 1;
      if (performance.now() - t0 < ms) requestAnimationFrame(tick); else done();
    };
    requestAnimationFrame(tick);
  });
  return frames / ((performance.now() - t0) / 1000);
}"""
BOXES_JS = "() => document.querySelectorAll('svg.stage-graph g.sg-vertex').length"
DOTS_JS = "() => document.querySelectorAll('svg.stage-graph circle.sg-dot').length"


def _choose(page: Any, label: str, option: str) -> None:
    page.get_by_label(label).click()
    page.get_by_role("option", name=option, exact=True).click()


def _phase(page: Any, pid: int, seconds: float) -> tuple[float, float]:
    """(page frames/s, dashboard CPU % of a core) over the same ``seconds``."""
    import threading

    cpu: dict[str, dict[str, float]] = {}
    sampler = threading.Thread(target=lambda: cpu.update(sample({"d": pid}, seconds)))
    sampler.start()
    fps = float(page.evaluate(FPS_JS, seconds * 1000))
    sampler.join()
    return fps, cpu["d"]["cpu_percent"]


def run(seconds: float, rounds: int) -> dict[str, Any]:
    from playwright.sync_api import sync_playwright

    require_private_netns("stage_graph")
    configure_dds(57)
    dashboard, url = start_dashboard("bench-stage-dashboard.log")
    load, log = spawn([sys.executable, "-c", LOAD], "bench-stage-load.log")
    try:
        wait_for_text(load, log, "STAGE LOAD READY", 60)
        with sync_playwright() as pw:
            browser = launch_browser(pw)
            context = browser.new_context(viewport={"width": 1366, "height": 768})
            page = context.new_page()
            page.goto(url)
            page.get_by_role("tab", name="Learn", exact=True).wait_for(timeout=30_000)
            _choose(page, "On stage", "Live ROS graph")
            started = time.monotonic()
            page.wait_for_function(f"() => ({BOXES_JS})() >= {3 * NODES}", timeout=60_000)
            shown_after = time.monotonic() - started
            time.sleep(4.0)  # rates settle: the dots are timed
            boxes, dots = page.evaluate(BOXES_JS), page.evaluate(DOTS_JS)
            on: list[tuple[float, float]] = []
            off: list[tuple[float, float]] = []
            # on, off, off, on, ...: a drift (a neighbour's load, a growing log) hits both alike.
            for phase in range(2 * rounds):
                graph = phase % 4 in (0, 3)
                _choose(page, "On stage", "Live ROS graph" if graph else "3D scene")
                time.sleep(2.0)
                (on if graph else off).append(_phase(page, dashboard.pid, seconds))
            browser.close()
        graph_fps, graph_cpu = (statistics.mean(v) for v in zip(*on, strict=True))
        off_fps, off_cpu = (statistics.mean(v) for v in zip(*off, strict=True))
    finally:
        stop(load)
        stop(dashboard)
    return {
        "seconds": seconds,
        "rounds": rounds,
        "nodes": NODES,
        "topics": 2 * NODES,
        "boxes_drawn": boxes,
        "dots_moving": dots,
        "graph_complete_s": shown_after,
        "stage_graph_fps": graph_fps,
        "stage_off_fps": off_fps,
        "stage_fps_ratio": graph_fps / off_fps if off_fps else float("nan"),
        "stage_graph_cpu_percent": graph_cpu,
        "stage_off_cpu_percent": off_cpu,
        "stage_extra_cpu_percent": graph_cpu - off_cpu,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench stage_graph")
    parser.add_argument("--seconds", type=float, default=10.0, help="per phase")
    parser.add_argument("--rounds", type=int, default=2, help="graph on / off alternations")
    args = parser.parse_args(argv)
    f = run(args.seconds, args.rounds)
    f["aim_met"] = bool(f["stage_graph_fps"] > 30 and f["stage_extra_cpu_percent"] < 5)
    print(
        f"stage graph ({f['boxes_drawn']} boxes, {f['dots_moving']} dots): page "
        f"{f['stage_graph_fps']:.1f} frames/s, stage off {f['stage_off_fps']:.1f} "
        f"(ratio {f['stage_fps_ratio']:.2f}; aim > 30 frames/s)"
    )
    print(
        f"dashboard CPU: graph on {f['stage_graph_cpu_percent']:.1f} % of a core, off "
        f"{f['stage_off_cpu_percent']:.1f} % -> extra {f['stage_extra_cpu_percent']:+.1f} % "
        "(aim < 5 %)"
    )
    print(json.dumps(rounded(f, 2), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
