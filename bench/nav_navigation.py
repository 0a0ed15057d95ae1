"""Benchmark: Nav2's navigation stack in the office: random goals reached, planning cost, CPU.

In one run, on the same machine: the ``office_navigation`` launch group as
the dashboard starts it (the office world at ``real_time_factor`` 2, camera
off; map_server with the office map, amcl told where the robot starts, the
planner, controller and navigator, brought up by the lifecycle manager),
each a process of its own. This process uses Nav2's Python API
(nav2_simple_commander's BasicNavigator) as a learner's script does.

- ``nav_success_percent``: ``--goals`` (20) random goals, seeded (``--seed``),
  drawn on the office's free floor at least 0.4 m from any obstacle of the
  world's floor plan and reachable on the planner's costmap from where the
  robot is, at least 1 m apart, sent one after another with ``goToPose``;
  a goal counts when the result is SUCCEEDED and the ground truth ends
  within 0.3 m of it (aim >= 95 %);
- ``nav_collisions``: times the robot's centre came closer than its radius
  (0.15 m) to an obstacle of the floor plan, by ground truth (aim 0), where
  (``collisions_at``), and ``nav_min_clearance_m`` the closest it came (where:
  ``min_clearance_at``);
- ``nav_path_ratio``: the driven length (ground truth) over the optimal
  8-connected grid path's length on the same map (cells the robot's radius
  fits in), summed over the goals reached (aim <= 1.2);
- ``nav_plan_p50_ms``: one plan through the planner server's
  ``compute_path_to_pose`` action (BasicNavigator.getPath, start and goal
  given: the round trip a client sees), between the same start and goal
  pairs, robot standing; ``nav_plan_inprocess_p50_ms`` the same plans by a
  plain call of the same planner code (nav2_planner's navfn planner) in this
  process on the same grid (the server's global costmap, read with
  ``BasicNavigator.getGlobalCostmap``); ``nav_plan_ratio``
  the first over the second (aim <= 1.5), ``nav_plan_server_p50_ms`` the
  server's own ``planning_time``. Each pair is planned ``--plan-repeats`` (3)
  times each way, in turn (``nav_plans_measured``: 60): with 20 plans a p50
  moved by more than the aim's margin between two quiet runs (1.28 to 1.59);
- ``nav_stack_cpu_percent``: the CPU of map_server, amcl, planner_server,
  controller_server and bt_navigator together while the goals are driven
  (per cent of one core, aim <= 100), and each of them in ``cpu_by_node``.

Beside them, ``nav_localization_error_max_m``: how far amcl's ``/amcl_pose`` was from
the ground truth at its stamp, at worst while driving (each goal's worst is printed
with it): a goal missed with a large one was lost by localization, not by planning
or control, and the first moment amcl was more than 0.5 m off is printed (and is
``localization_lost`` in the JSON): where its pose jumped from and to, and where the robot
really went meanwhile.

The stack's logs are kept in ``test-artifacts/bench-nav_navigation.log``.
Also ``rtf_kept`` (simulated over wall seconds while driving) and the load
average at the start: others on the cores stretch every wall time.

A figure that cannot be measured is NaN (``null`` in the JSON) with the
reason printed as a ``FAILED:`` line, and the benchmark exits 1.

Run: ``.venv/bin/python tests/run.py --bench nav_navigation [--goals N]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import collections
import json
import math
import os
import random
import threading
import time
from typing import Any

from bench._common import LOGS, configure_dds, percentile, require_private_netns, rounded

AIM_SUCCESS_PERCENT = 95.0
AIM_PATH_RATIO = 1.2
AIM_PLAN_RATIO = 1.5
AIM_CPU_PERCENT = 100.0
CLEARANCE = 0.4  # m: goals this far from any obstacle
REACHED = 0.3  # m: the ground truth this close to the goal at the end
LOST = 0.5  # m: amcl this far from the ground truth has lost the robot
ROBOT_RADIUS = 0.15  # m: the costmap's robot_radius; closer than this is a collision
MIN_LEG = 1.0  # m between consecutive goals
GOAL_TIMEOUT = 120.0  # s wall for one goal
FASTER = ("-p", "camera_rate:=0.0")
STACK = {  # catalog member -> the process name in cpu_by_node
    "map_server_office": "map_server",
    "amcl_office": "amcl",
    "planner_server": "planner_server",
    "controller_server": "controller_server",
    "bt_navigator": "bt_navigator",
}


def office_costmap() -> Any:
    """The office map as the planner server's global costmap (the same parameters).

    Its static and inflation layers; the server's obstacle layer adds what /scan sees off
    the map, and in the office with the robot standing that is the mapped walls again (a
    cell thicker here and there, as far as localization is off).
    """
    import numpy as np
    from nav2_costmap_2d.costmap_2d import costmap_from_grid
    from nav2_map_server.map_io import load_map_from_yaml

    from app import PROJECT_ROOT

    loaded = load_map_from_yaml(str(PROJECT_ROOT / "nodes" / "worlds" / "office" / "map.yaml"))
    grid = loaded.map
    if grid is None:
        raise RuntimeError(f"the office map did not load: {loaded.reason}")
    info = grid.info
    data = np.asarray(grid.data, np.int8).reshape(info.height, info.width)
    return costmap_from_grid(
        data, info.resolution, (info.origin.position.x, info.origin.position.y)
    )


def server_costmap(msg: Any) -> Any:
    """A ``nav2_msgs/Costmap`` (GetCostmap's answer) as the planner's Costmap2D."""
    import numpy as np
    from nav2_costmap_2d.costmap_2d import Costmap2D

    meta = msg.metadata
    if meta.size_x == 0 or meta.size_y == 0:
        raise RuntimeError("the planner server's global costmap is empty")
    costs = np.asarray(msg.data, np.uint8).reshape(meta.size_y, meta.size_x)
    origin = meta.origin.position
    return Costmap2D(costs, float(meta.resolution), origin.x, origin.y, msg.header.frame_id)


def grid_lengths(costmap: Any, start: tuple[float, float]) -> tuple[Any, Any]:
    """Shortest 8-connected lengths (m) from ``start`` over the cells the robot fits in."""
    import numpy as np
    from nav2_costmap_2d.cost_values import INSCRIBED_INFLATED_OBSTACLE
    from nav2_planner.navfn_planner import search

    weight = np.where(costmap.costs >= INSCRIBED_INFLATED_OBSTACLE, math.inf, 1.0)
    cell = costmap.world_to_map(*start)
    if cell is None:
        raise RuntimeError(f"the robot at {start} is off the map")
    weight[cell[1], cell[0]] = 1.0
    _came_from, best = search(weight, cell, None, False)
    return best, weight


def draw_goals(
    costmap: Any, obstacles: Any, start: tuple[float, float], count: int, seed: int
) -> list[tuple[float, float, float]]:
    """``count`` goals on free floor >= CLEARANCE from obstacles, reachable, >= MIN_LEG apart."""
    import numpy as np

    from nodes.common.occupancy_grid import plan_distance

    best, _weight = grid_lengths(costmap, start)
    w = costmap.size_x
    cells = np.array(sorted(best), np.int64)
    ys, xs = np.divmod(cells, w)
    wx = costmap.origin_x + (xs + 0.5) * costmap.resolution
    wy = costmap.origin_y + (ys + 0.5) * costmap.resolution
    clear = plan_distance(obstacles, wx, wy) >= CLEARANCE
    candidates = list(zip(wx[clear].tolist(), wy[clear].tolist(), strict=True))
    if not candidates:
        raise RuntimeError("no free floor 0.4 m from the obstacles is reachable")
    rng = random.Random(seed)
    goals: list[tuple[float, float, float]] = []
    here = start
    while len(goals) < count:
        x, y = rng.choice(candidates)
        if math.hypot(x - here[0], y - here[1]) < MIN_LEG:
            continue
        goals.append((x, y, rng.uniform(-math.pi, math.pi)))
        here = (x, y)
    return goals


def run(goals_n: int, seed: int, rtf: float, plan_repeats: int = 3) -> dict[str, Any]:
    import psutil
    import rclpy
    from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
    from nav2_planner.navfn_planner import PlannerOptions, create_plan
    from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult
    from nav_msgs.msg import Odometry
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import DurabilityPolicy, QoSProfile

    from app.catalog import lookup_group
    from app.lessons.checks._world_map import load_world_map
    from app.supervisor import Supervisor
    from nodes.common.occupancy_grid import plan_distance

    require_private_netns("nav_navigation")
    configure_dds(83)
    figures: dict[str, Any] = {"goals": goals_n, "seed": seed, "rtf_asked": rtf, "errors": []}
    figures["load_average"] = os.getloadavg()[0]  # others on the cores stretch wall times
    obstacles = load_world_map("office").obstacles
    supervisor = Supervisor(dict(os.environ), max_log_lines=20_000)
    rclpy.init()
    observer = rclpy.create_node("bench_nav_navigation")
    executor = SingleThreadedExecutor()
    executor.add_node(observer)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    lock = threading.Lock()
    truth: dict[str, Any] = {"pose": None, "t": 0.0, "path": 0.0, "record": False}
    recent: collections.deque[tuple[float, float, float]] = collections.deque(maxlen=300)
    localization = {"worst": 0.0, "samples": 0}  # amcl against the truth, while recording
    clearance: dict[str, Any] = {
        "min": math.inf,
        "min_at": None,
        "collisions": 0,
        "inside": False,
        "at": [],
    }

    def on_truth(msg: Any) -> None:
        p = msg.pose.pose.position
        t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        import numpy as np

        d = float(plan_distance(obstacles, np.array([p.x]), np.array([p.y]))[0])
        with lock:
            last = truth["pose"]
            if truth["record"] and last is not None:
                truth["path"] += math.hypot(p.x - last[0], p.y - last[1])
            truth["pose"], truth["t"] = (p.x, p.y), t
            recent.append((t, p.x, p.y))
            judge_unjudged()
            if d < clearance["min"]:
                clearance["min"], clearance["min_at"] = d, (round(p.x, 2), round(p.y, 2))
            if d < ROBOT_RADIUS and not clearance["inside"]:
                clearance["collisions"] += 1
                clearance["at"].append((round(p.x, 2), round(p.y, 2)))
            clearance["inside"] = d < ROBOT_RADIUS

    # amcl's poses wait for the truth of their stamp: on a busy machine this process heard
    # the truth up to 0.6 s late, and the newest truth it had then was the robot's older pose
    # (0.22 m "off" where amcl was right).
    unjudged: collections.deque[tuple[float, float, float]] = collections.deque(maxlen=300)

    # The first moment amcl lost the robot, said once: where its pose went from and to, and
    # where the robot really went meanwhile (a jump, or a slow drift, tells the cause apart).
    judged: list[tuple[float, float, float, float, float]] = []  # the last: t, amcl x y, truth x y
    lost_at: list[str] = []

    def judge_unjudged() -> None:  # with the lock held
        while unjudged and recent and recent[-1][0] >= unjudged[0][0]:
            t, ax, ay = unjudged.popleft()
            _t, x, y = min(recent, key=lambda r: abs(r[0] - t))  # the truth at its stamp
            off = math.hypot(ax - x, ay - y)
            if off > LOST and judged and not lost_at:
                t0, ax0, ay0, x0, y0 = judged[-1]
                lost_at.append(
                    f"amcl lost the robot at {t:.1f} s of simulated time: its pose went from "
                    f"({ax0:.2f}, {ay0:.2f}) to ({ax:.2f}, {ay:.2f}) in {t - t0:.1f} s while the "
                    f"robot went from ({x0:.2f}, {y0:.2f}) to ({x:.2f}, {y:.2f})"
                )
                print(f"  {lost_at[0]}", flush=True)
            judged[:] = [(t, ax, ay, x, y)]
            localization["worst"] = max(localization["worst"], off)
            localization["samples"] += 1

    def on_amcl(msg: Any) -> None:
        t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        p = msg.pose.pose.position
        with lock:
            if truth["record"]:
                unjudged.append((t, p.x, p.y))
                judge_unjudged()

    observer.create_subscription(Odometry, "/ground_truth/odom", on_truth, 50)
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    observer.create_subscription(PoseWithCovarianceStamped, "/amcl_pose", on_amcl, latched)
    spinner.start()
    nav: Any = None

    def stamped(x: float, y: float, yaw: float) -> Any:
        pose = PoseStamped()
        pose.header.frame_id = "map"
        pose.header.stamp = nav.get_clock().now().to_msg()
        pose.pose.position.x, pose.pose.position.y = x, y
        pose.pose.orientation.z, pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        return pose

    def bounded(work: Any, timeout: float, what: str) -> None:
        failure: list[BaseException] = []

        def target() -> None:
            try:
                work()
            except BaseException as exc:
                failure.append(exc)

        worker = threading.Thread(target=target, daemon=True)
        worker.start()
        worker.join(timeout)
        if worker.is_alive():
            raise RuntimeError(f"{what} within {timeout:.0f} s")
        if failure:
            raise failure[0]

    def robot() -> tuple[float, float]:
        deadline = time.monotonic() + 60.0
        while True:
            with lock:
                pose = truth["pose"]
            if pose is not None:
                return pose
            if time.monotonic() > deadline:
                raise RuntimeError("no /ground_truth/odom within 60 s")
            time.sleep(0.1)

    try:
        group = lookup_group("office_navigation")
        for member in group.members:
            extra = (*FASTER, "-p", f"real_time_factor:={rtf}") if member.startswith("sim_") else ()
            supervisor.start(member, extra)
        nav = BasicNavigator()
        bounded(nav.waitUntilNav2Active, 180, "Nav2 did not become active")
        costmap = office_costmap()
        start = robot()
        goals = draw_goals(costmap, obstacles, start, goals_n, seed)

        # Planning: the server's action against the same code in this process, robot standing,
        # on the server's own grid (its obstacle layer marks what /scan sees, so it is not
        # quite the map's: about 3,000 of 39,600 cells differ) as BasicNavigator reads it.
        options = PlannerOptions()  # GridBased's defaults, as the server runs it
        served = server_costmap(nav.getGlobalCostmap())
        action_ms, server_ms, local_ms = [], [], []
        here = (start[0], start[1], 0.0)
        for goal in goals:
            for _ in range(plan_repeats):  # both ways in turn, so a slow moment hits both
                t0 = time.perf_counter()
                path = nav._getPathImpl(stamped(*here), stamped(*goal), "", True)
                elapsed = time.perf_counter() - t0
                if path is None or not path.path.poses:
                    raise RuntimeError(f"compute_path_to_pose found no path from {here} to {goal}")
                action_ms.append(1000.0 * elapsed)
                pt = path.planning_time
                server_ms.append(pt.sec * 1000.0 + pt.nanosec / 1e6)
                t0 = time.perf_counter()
                create_plan(served, here, goal, options)
                local_ms.append(1000.0 * (time.perf_counter() - t0))
            here = goal
        figures["nav_plans_measured"] = len(action_ms)
        figures["nav_plan_p50_ms"] = percentile(action_ms, 50)
        figures["nav_plan_server_p50_ms"] = percentile(server_ms, 50)
        figures["nav_plan_inprocess_p50_ms"] = percentile(local_ms, 50)
        figures["nav_plan_ratio"] = (
            figures["nav_plan_p50_ms"] / figures["nav_plan_inprocess_p50_ms"]
        )

        # Driving: the goals one after another.
        procs = {
            STACK[m]: psutil.Process(supervisor.status(m).pid) for m in STACK if m in group.members
        }
        cpu0 = {name: sum(p.cpu_times()[:2]) for name, p in procs.items()}
        wall0 = time.monotonic()
        with lock:
            sim0 = truth["t"]
        reached, driven, optimal, outcomes = 0, 0.0, 0.0, []
        worst_localization = 0.0
        for k, goal in enumerate(goals):
            here2 = robot()
            best, _w = grid_lengths(costmap, here2)
            cell = costmap.world_to_map(goal[0], goal[1])
            shortest = best.get(cell[1] * costmap.size_x + cell[0], math.nan) * costmap.resolution
            with lock:
                truth["path"], truth["record"] = 0.0, True
                localization["worst"] = 0.0
            t0 = time.monotonic()
            if not nav.goToPose(stamped(*goal)):
                outcomes.append("rejected")
                continue

            def until_done() -> None:
                while not nav.isTaskComplete():
                    pass

            try:
                bounded(until_done, GOAL_TIMEOUT, "the goal did not end")
                result = nav.getResult()
            except RuntimeError:
                nav.cancelTask()
                result = TaskResult.UNKNOWN
            time.sleep(0.3)  # the last ground truth
            with lock:
                truth["record"] = False
                length = truth["path"]
                lost = localization["worst"]
                worst_localization = max(worst_localization, lost)
            x, y = robot()
            error = math.hypot(x - goal[0], y - goal[1])
            ok = result == TaskResult.SUCCEEDED and error < REACHED
            if ok:
                reached += 1
                driven += length
                optimal += shortest
            outcomes.append(f"{result.name.lower()} {error:.2f} m")
            print(
                f"  goal {k + 1}/{len(goals)} ({goal[0]:.2f}, {goal[1]:.2f}): {result.name}, "
                f"ended {error:.2f} m away, drove {length:.2f} m (grid optimum "
                f"{shortest:.2f} m) in {time.monotonic() - t0:.1f} s; amcl off by {lost:.2f} m "
                "at worst",
                flush=True,
            )
        wall = time.monotonic() - wall0
        cpu = {
            name: 100.0 * (sum(p.cpu_times()[:2]) - cpu0[name]) / wall for name, p in procs.items()
        }
        with lock:
            sim1 = truth["t"]
        figures["cpu_by_node"] = cpu
        figures["nav_stack_cpu_percent"] = sum(cpu.values())
        figures["drive_wall_sec"] = wall
        figures["rtf_kept"] = (sim1 - sim0) / wall if wall > 0 else math.nan
        figures["nav_success_percent"] = 100.0 * reached / len(goals)
        figures["nav_path_ratio"] = driven / optimal if optimal > 0 else math.nan
        figures["outcomes"] = outcomes
        with lock:
            compared = localization["samples"]
        if compared:
            figures["nav_localization_error_max_m"] = worst_localization
            figures["localization_lost"] = lost_at[0] if lost_at else None
        else:
            figures["errors"].append("no /amcl_pose came while the goals were driven")
        with lock:
            figures["nav_collisions"] = clearance["collisions"]
            figures["nav_min_clearance_m"] = clearance["min"]
            figures["min_clearance_at"] = clearance["min_at"]
            figures["collisions_at"] = list(clearance["at"])
    except Exception as exc:  # reported, never quiet
        figures["errors"].append(str(exc))
    finally:
        try:
            if nav is not None:
                nav.destroyNode()
        except Exception:
            pass
        try:  # the stack's own words, for a goal that went wrong
            LOGS.mkdir(exist_ok=True)
            with open(LOGS / "bench-nav_navigation.log", "w") as out:
                for member in lookup_group("office_navigation").members:
                    out.write(f"--- {member}\n" + "\n".join(supervisor.output(member)) + "\n")
        except OSError:
            pass
        executor.shutdown(timeout_sec=2.0)
        observer.destroy_node()
        rclpy.try_shutdown()
        supervisor.shutdown()
    for key in (
        "nav_success_percent",
        "nav_collisions",
        "nav_min_clearance_m",
        "nav_path_ratio",
        "nav_plan_p50_ms",
        "nav_plan_server_p50_ms",
        "nav_plan_inprocess_p50_ms",
        "nav_plan_ratio",
        "nav_stack_cpu_percent",
        "nav_localization_error_max_m",
    ):
        figures.setdefault(key, math.nan)
    return figures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench nav_navigation")
    parser.add_argument("--goals", type=int, default=20, help="random goals to drive to")
    parser.add_argument("--seed", type=int, default=40, help="the goals' random seed")
    parser.add_argument("--rtf", type=float, default=2.0, help="the world's real_time_factor")
    parser.add_argument(
        "--plan-repeats", type=int, default=3, help="plans between each pair of goals, each way"
    )
    args = parser.parse_args(argv)
    f = run(max(args.goals, 1), args.seed, args.rtf, max(args.plan_repeats, 1))
    f["aim_met"] = bool(
        f["nav_success_percent"] >= AIM_SUCCESS_PERCENT
        and f["nav_collisions"] == 0
        and f["nav_path_ratio"] <= AIM_PATH_RATIO
        and f["nav_plan_ratio"] <= AIM_PLAN_RATIO
        and f["nav_stack_cpu_percent"] <= AIM_CPU_PERCENT
    )
    print(
        f"Nav2 in the office, {f['goals']} random goals (seed {f['seed']}): "
        f"{f['nav_success_percent']:.0f} % reached within {REACHED:g} m "
        f"(aim >= {AIM_SUCCESS_PERCENT:g}), {f['nav_collisions']} collisions (aim 0), "
        f"closest {f['nav_min_clearance_m']:.3f} m; driven / optimal grid path "
        f"{f['nav_path_ratio']:.2f} (aim <= {AIM_PATH_RATIO:g})"
    )
    print(
        f"  planning through compute_path_to_pose p50 {f['nav_plan_p50_ms']:.0f} ms (the "
        f"server's own {f['nav_plan_server_p50_ms']:.0f} ms) against the same planner in "
        f"this process {f['nav_plan_inprocess_p50_ms']:.0f} ms: ratio "
        f"{f['nav_plan_ratio']:.2f} (aim <= {AIM_PLAN_RATIO:g})"
    )
    print(
        f"  map_server + amcl + planner + controller + bt_navigator while driving: "
        f"{f['nav_stack_cpu_percent']:.0f} % of one core (aim <= {AIM_CPU_PERCENT:g}); "
        f"world at {f.get('rtf_kept', math.nan):.2f}x real time (asked {f['rtf_asked']:g}); "
        f"1-minute load average at the start {f.get('load_average', math.nan):.1f}"
    )
    for error in f["errors"]:
        print(f"FAILED: not measured: {error}")
    print(json.dumps(rounded(f, 3), sort_keys=True))
    return 1 if f["errors"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
