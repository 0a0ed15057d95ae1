"""Benchmark: how well grid_mapper maps the office after a scripted tour.

In one run, on the same machine: sim_world with the office world
(``publish_world_tf:=false``, camera off, ``real_time_factor`` 3 by default),
its robot_state_publisher and grid_mapper, started as the ``office_mapping``
launch group starts them (without the keyboard teleop), as processes of
their own. This process drives the robot on /cmd_vel through every room (a
go-to-point controller on the ground truth, 19 waypoints, about 38 m), then
takes the latched /map stamped after the tour's end and compares it cell by
cell with the world file's floor plan (``app.lessons.checks._world_map``):

- ``map_agreement_percent``: of the cells the map knows (free or occupied),
  how many agree with the plan (an occupied cell has an obstacle reaching
  into it; a free cell's centre is in no obstacle). Aim >= 95 (issue 40);
- ``map_coverage_percent``: of the plan's floor the robot can reach (points
  0.1 m or more from any obstacle, joined to the start), how much the map calls free;
- ``occupied_agree_percent`` and ``free_agree_percent`` apart, the map's size,
  the tour's simulated and wall seconds, the real-time factor the world kept,
  the mapper's CPU (per cent of one core) and the closest the robot's body
  came to an obstacle (from the ground truth: a collision is <= 0).

A figure that cannot be measured is NaN (``null`` in the JSON) with the
reason printed as a ``FAILED:`` line, and the benchmark exits 1.

Run: ``.venv/bin/python tests/run.py --bench nav_mapping [--rtf R]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import math
import threading
import time
from typing import Any

import numpy as np

from bench._common import configure_dds, require_private_netns, rounded
from nodes.office_tour import REACHED, TOUR, command  # the tour office_tour drives

AIM_PERCENT = 95.0
MEMBERS = ("sim_office_mapping", "sim_robot_state_publisher", "grid_mapper")


def plan_figures(msg: Any) -> dict[str, float]:
    from app.lessons.checks._world_map import load_world_map
    from nodes.common.occupancy_grid import (
        cell_centres,
        floor_coverage,
        floor_points,
        map_agreement,
        map_values_at,
        plan_distance,
    )

    plan = load_world_map("office")
    origin = (msg.info.origin.position.x, msg.info.origin.position.y)
    size = (msg.info.resolution, msg.info.width, msg.info.height)
    xs, ys = cell_centres(origin, *size)
    distance = plan_distance(plan.obstacles, xs, ys)
    data = np.array(msg.data, np.int8).reshape(distance.shape)
    result = map_agreement(data, distance, msg.info.resolution)
    floor = map_values_at(data, origin, *size, *floor_points(plan.obstacles))
    return {
        "map_agreement_percent": result.percent,
        "occupied_agree_percent": 100.0 * result.occupied_agree / max(result.occupied, 1),
        "free_agree_percent": 100.0 * result.free_agree / max(result.free, 1),
        "known_cells": result.known,
        "occupied_cells": result.occupied,
        "map_coverage_percent": floor_coverage(floor),
        "map_width": msg.info.width,
        "map_height": msg.info.height,
    }


def run(rtf: float) -> dict[str, Any]:
    import psutil
    import rclpy
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import OccupancyGrid, Odometry
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    from app.catalog import lookup
    from app.lessons.checks._world_map import load_world_map
    from app.supervisor import Supervisor

    require_private_netns("nav_mapping")
    configure_dds(70)
    figures: dict[str, Any] = {"rtf_asked": rtf, "waypoints": len(TOUR), "errors": []}
    plan = load_world_map("office")
    import os

    supervisor = Supervisor(dict(os.environ))
    rclpy.init()
    node = rclpy.create_node("bench_nav_mapping")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    lock = threading.Lock()
    state: dict[str, Any] = {"truth": None, "map": None, "clearance": math.inf}

    def on_truth(msg: Odometry) -> None:
        q = msg.pose.pose.orientation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        x, y = msg.pose.pose.position.x, msg.pose.pose.position.y
        near = plan.clearance(x, y, yaw).distance
        with lock:
            state["truth"] = (t, x, y, yaw)
            state["clearance"] = min(state["clearance"], near)

    def on_map(msg: OccupancyGrid) -> None:
        with lock:
            state["map"] = msg

    latched = QoSProfile(
        depth=1,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    node.create_subscription(Odometry, "/ground_truth/odom", on_truth, 10)
    node.create_subscription(OccupancyGrid, "/map", on_map, latched)
    cmd = node.create_publisher(Twist, "/cmd_vel", 10)
    try:
        sim_args = ("-p", "camera_rate:=0.0", "-p", f"real_time_factor:={rtf}")
        supervisor.start_program(lookup(MEMBERS[0]), sim_args)
        for member in MEMBERS[1:]:
            supervisor.start(member)
        deadline = time.monotonic() + 90.0
        while time.monotonic() < deadline:
            with lock:
                ready = state["truth"] is not None and state["map"] is not None
            if ready:
                break
            time.sleep(0.1)
        else:
            raise RuntimeError("no /map and ground truth within 90 s")
        mapper = psutil.Process(supervisor.status("grid_mapper").pid)
        cpu0 = sum(mapper.cpu_times()[:2])
        with lock:
            sim0 = state["truth"][0]
        wall0 = time.monotonic()
        for goal in TOUR:
            leg_deadline = time.monotonic() + 120.0
            while True:
                with lock:
                    _t, x, y, yaw = state["truth"]
                if math.dist((x, y), goal) < REACHED:
                    break
                if time.monotonic() > leg_deadline:
                    raise RuntimeError(f"waypoint {goal} not reached (robot at {x:.2f}, {y:.2f})")
                linear, angular = command((x, y, yaw), goal)
                twist = Twist()
                twist.linear.x, twist.angular.z = linear, angular
                cmd.publish(twist)
                time.sleep(0.05)
        cmd.publish(Twist())
        wall = time.monotonic() - wall0
        with lock:
            end = state["truth"][0]
        figures["tour_sim_sec"] = end - sim0
        figures["tour_wall_sec"] = wall
        figures["rtf_kept"] = (end - sim0) / wall
        figures["mapper_cpu_percent"] = 100.0 * (sum(mapper.cpu_times()[:2]) - cpu0) / wall
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline:
            with lock:
                msg = state["map"]
            stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
            if stamp >= end:
                break
            time.sleep(0.1)
        else:
            raise RuntimeError("no /map stamped after the tour within 30 s")
        figures.update(plan_figures(msg))
        with lock:
            figures["min_clearance_m"] = state["clearance"]
    except Exception as exc:  # reported, never quiet
        figures["errors"].append(str(exc))
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
        supervisor.shutdown()
    for key in ("map_agreement_percent", "map_coverage_percent", "tour_sim_sec"):
        figures.setdefault(key, math.nan)
    return figures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench nav_mapping")
    parser.add_argument("--rtf", type=float, default=3.0, help="the world's real_time_factor")
    args = parser.parse_args(argv)
    f = run(args.rtf)
    f["aim_met"] = bool(f["map_agreement_percent"] >= AIM_PERCENT)
    print(
        f"grid_mapper after a {f['tour_sim_sec']:.0f} s (simulated) tour of the office: "
        f"{f['map_agreement_percent']:.1f} % of {f.get('known_cells', 0)} known cells agree "
        f"with the floor plan (aim >= {AIM_PERCENT:g}); it calls "
        f"{f['map_coverage_percent']:.0f} % of the free floor free"
    )
    if "mapper_cpu_percent" in f:
        print(
            f"  occupied cells right {f['occupied_agree_percent']:.1f} %, free cells right "
            f"{f['free_agree_percent']:.1f} %; world at {f['rtf_kept']:.2f}x real time "
            f"(asked {f['rtf_asked']:g}), mapper {f['mapper_cpu_percent']:.0f} % of a core, "
            f"closest approach {f['min_clearance_m']:.3f} m"
        )
    for error in f["errors"]:
        print(f"FAILED: not measured: {error}")
    print(json.dumps(rounded(f, 3), sort_keys=True))
    return 1 if f["errors"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
