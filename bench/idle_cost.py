"""Benchmark: what an idle dashboard costs, against an idle plain rclpy node process.

The dashboard (``ros2-classroom serve``) runs with one headless Chromium page
attached and no tutorial nodes; the baseline is a plain rclpy node spinning
with nothing to do, in its own process, at the same time. Both are sampled
with psutil over the same seconds: CPU (user + system, % of one core) and
memory (RSS and USS).

Run: ``.venv/bin/python tests/run.py --bench idle_cost [--seconds S]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

from bench._common import (
    configure_dds,
    launch_browser,
    open_dashboard,
    require_private_netns,
    rounded,
    sample,
    spawn,
    start_dashboard,
    stop,
    wait_for_text,
)

PLAIN_NODE = """
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
rclpy.init()
node = Node("bench_idle_node")
print("IDLE NODE READY", flush=True)
try:
    rclpy.spin(node)
except (KeyboardInterrupt, ExternalShutdownException):
    pass
finally:
    rclpy.try_shutdown()
"""


def run(seconds: float) -> dict[str, Any]:
    from playwright.sync_api import sync_playwright

    require_private_netns("idle_cost")
    configure_dds(30)
    dashboard, url = start_dashboard("bench-idle-dashboard.log")
    plain, log = spawn([sys.executable, "-c", PLAIN_NODE], "bench-idle-node.log")
    try:
        wait_for_text(plain, log, "IDLE NODE READY", 30)
        with sync_playwright() as pw:
            browser = launch_browser(pw)
            open_dashboard(browser, url)
            time.sleep(3.0)  # start-up and the first page's traffic are not idle
            figures = sample({"dashboard": dashboard.pid, "plain": plain.pid}, seconds)
            browser.close()
    finally:
        stop(plain)
        stop(dashboard)
    dash, base = figures["dashboard"], figures["plain"]
    return {
        "seconds": seconds,
        "idle_cpu_dashboard_percent": dash["cpu_percent"],
        "idle_cpu_plain_percent": base["cpu_percent"],
        "idle_cpu_delta_percent": dash["cpu_percent"] - base["cpu_percent"],
        "idle_rss_dashboard_mb": dash["rss_mb"],
        "idle_rss_plain_mb": base["rss_mb"],
        "idle_uss_dashboard_mb": dash["uss_mb"],
        "idle_uss_plain_mb": base["uss_mb"],
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench idle_cost")
    parser.add_argument("--seconds", type=float, default=10.0)
    args = parser.parse_args(argv)
    f = run(args.seconds)
    f["aim_met"] = bool(f["idle_cpu_delta_percent"] <= 5.0)
    print(
        f"idle CPU: dashboard {f['idle_cpu_dashboard_percent']:.1f} % of a core, plain rclpy "
        f"node {f['idle_cpu_plain_percent']:.1f} % -> +{f['idle_cpu_delta_percent']:.1f} % "
        "(aim <= 5 %)"
    )
    print(
        f"memory: dashboard RSS {f['idle_rss_dashboard_mb']:.0f} MB (USS "
        f"{f['idle_uss_dashboard_mb']:.0f}), plain node RSS {f['idle_rss_plain_mb']:.0f} MB "
        f"(USS {f['idle_uss_plain_mb']:.0f})"
    )
    print(json.dumps(rounded(f, 2), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
