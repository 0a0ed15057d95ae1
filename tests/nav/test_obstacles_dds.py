"""Obstacles the map does not have, over real DDS: Nav2 sees them in /scan and drives round them.

The office world with two boxes added that the shipped map does not know
(the world file is written for the test: the office's, plus the boxes): one
in the corridor, 3 m east of where the robot starts (out of the obstacle
layer's 2.5 m reach at the start, so the first plan runs through it), one
closing the lounge's only door. Map server, planner, controller and
navigator as the dashboard starts them, brought up by the lifecycle manager;
where the robot is comes from the simulator (world -> odom) and the map is
the world frame (no amcl: this is about the costmaps, the planner and the
controller, and should not hang on localization). Then NavigateToPose goals
from an ActionClient (the thread-safe one: see test_navigation_dds.py):

- along the corridor past the box: the costmaps mark the box from /scan,
  the navigator's new plans go round it, the robot arrives and never comes
  closer to the box or a wall than its radius (by ground truth);
- into the lounge: the box in its door closes the only way in, and the goal
  ends aborted with ComputePathToPose's NO_VALID_PATH, the robot standing;
- west along the corridor, cancelled on the way: the robot stops within 0.5 s.
"""

from __future__ import annotations

import math
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from action_msgs.msg import GoalStatus
from nav2_msgs.action import ComputePathToPose, NavigateToPose
from nav_msgs.msg import OccupancyGrid, Odometry
from nav_msgs.msg import Path as PathMsg
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_srvs.srv import Trigger

from app import PROJECT_ROOT
from app.catalog import lookup
from app.lessons.checks._world_map import load_world_map
from app.ros.action_client import ThreadSafeActionClient
from nodes.common.occupancy_grid import plan_distance
from tests.conftest import wait_until
from tests.nav.goal_helpers import parameter, pose_stamped, wait_future

pytestmark = [pytest.mark.ros, pytest.mark.timeout(180)]

LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
OFFICE = PROJECT_ROOT / "nodes" / "worlds" / "office"
SIM_ARGS = ("-p", "camera_rate:=0.0", "-p", "real_time_factor:=2.0")
MANAGED = ["map_server", "planner_server", "controller_server", "bt_navigator"]
RADIUS = 0.15  # m: the costmaps' robot_radius; closer than this to anything is a collision
# (x, y, half_x, half_y): boxes on the floor, 0.5 m high, not on the map
CORRIDOR_BOX = (3.0, -0.05, 0.15, 0.15)  # on the corridor's middle line, 0.55 m free beside
DOOR_BOX = (1.45, -0.8, 0.5, 0.05)  # fills the lounge's door (x = 1.0..1.9)
EAST_GOAL = (4.3, -0.1, 0.0)  # the corridor's east end, past the corridor box
LOUNGE_GOAL = (1.45, -2.0, -math.pi / 2)  # behind the blocked door
WEST_GOAL = (-2.0, 0.0, math.pi)  # cancelled on the way
STOPPED = 0.02  # m/s


def world_with_boxes(folder: Path) -> Path:
    """The office world file with the two boxes, its robot model found from anywhere."""
    text = (OFFICE / "world.xml").read_text()
    robot = (OFFICE / ".." / ".." / "robots" / "diffbot" / "robot.xml").resolve()
    text = text.replace('file="../../robots/diffbot/robot.xml"', f'file="{robot}"')
    boxes = "".join(
        f'<geom name="test_box_{k}" type="box" size="{hx} {hy} 0.25" pos="{x} {y} 0.25" '
        'rgba="0.9 0.3 0.2 1"/>\n'
        for k, (x, y, hx, hy) in enumerate((CORRIDOR_BOX, DOOR_BOX))
    )
    assert text.count("<frame pos") == 1
    text = text.replace("<frame pos", boxes + "<frame pos")
    path = folder / "office_with_boxes.xml"
    path.write_text(text)
    return path


def box_distance(box: tuple[float, float, float, float], x: Any, y: Any) -> np.ndarray:
    cx, cy, hx, hy = box
    qx, qy = np.abs(np.asarray(x) - cx) - hx, np.abs(np.asarray(y) - cy) - hy
    return np.hypot(np.maximum(qx, 0.0), np.maximum(qy, 0.0)) + np.minimum(np.maximum(qx, qy), 0)


class Truth:
    """The robot's true pose and speed, and its closest approach to the walls and the boxes."""

    def __init__(self, node: Any) -> None:
        self.lock = threading.Lock()
        self.pose: tuple[float, float] | None = None
        self.speed = 0.0
        self.closest = math.inf
        self.closest_at: tuple[float, ...] | None = None  # x, y, speed, seconds into the test
        self.nearest = {"walls": math.inf, "corridor box": math.inf, "door box": math.inf}
        self.started = time.monotonic()
        self.obstacles = load_world_map("office").obstacles
        node.create_subscription(Odometry, "/ground_truth/odom", self.on_truth, 10)

    def on_truth(self, msg: Odometry) -> None:
        p = msg.pose.pose.position
        x, y = np.array([p.x]), np.array([p.y])
        each = {
            "walls": float(plan_distance(self.obstacles, x, y)[0]),
            "corridor box": float(box_distance(CORRIDOR_BOX, x, y)[0]),
            "door box": float(box_distance(DOOR_BOX, x, y)[0]),
        }
        d = min(each.values())
        tw = msg.twist.twist.linear
        with self.lock:
            for name, distance in each.items():
                self.nearest[name] = min(self.nearest[name], round(distance, 3))
            self.pose = (p.x, p.y)
            self.speed = math.hypot(tw.x, tw.y)
            if d < self.closest:
                when = time.monotonic() - self.started
                where = (round(p.x, 2), round(p.y, 2), round(self.speed, 2), round(when, 2))
                self.closest, self.closest_at = d, where

    def get(self) -> tuple[float, float]:
        wait_until(lambda: self.pose, timeout=60, what="/ground_truth/odom")
        with self.lock:
            assert self.pose is not None
            return self.pose


def cost_near(grid: OccupancyGrid, x: float, y: float, reach: float = 0.1) -> int:
    """The highest published cost within ``reach`` of a point (OccupancyGrid values)."""
    info = grid.info
    data = np.asarray(grid.data, np.int16).reshape(info.height, info.width)
    r = int(math.ceil(reach / info.resolution))
    mx = int((x - info.origin.position.x) / info.resolution)
    my = int((y - info.origin.position.y) / info.resolution)
    return int(data[max(my - r, 0) : my + r + 1, max(mx - r, 0) : mx + r + 1].max())


def test_boxes_not_on_the_map_are_driven_round_or_reported_and_a_cancel_stops_at_once(
    probe, supervisor, tmp_path
):
    started = time.monotonic()
    node = probe.node
    truth = Truth(node)
    plans: list[PathMsg] = []
    node.create_subscription(PathMsg, "/plan", plans.append, 10)
    costmaps: list[OccupancyGrid] = []
    node.create_subscription(OccupancyGrid, "/global_costmap/costmap", costmaps.append, LATCHED)
    world = world_with_boxes(tmp_path)
    supervisor.start_program(lookup("sim_office"), (*SIM_ARGS, "-p", f"world:={world}"))
    for name in ("sim_robot_state_publisher", "office_map_world", "map_server_office"):
        supervisor.start(name)
    for name in ("planner_server", "controller_server", "bt_navigator"):
        supervisor.start(name)
    supervisor.start("lifecycle_manager_navigation", ("-p", f"node_names:=[{','.join(MANAGED)}]"))
    truth.get()

    def logs() -> str:
        names = ("sim_office", "planner_server", "controller_server", "bt_navigator",
                 "lifecycle_manager_navigation")  # fmt: skip
        return "\n".join(f"--- {n}\n" + "\n".join(supervisor.output(n, last=25)) for n in names)

    is_active = node.create_client(Trigger, "/lifecycle_manager_navigation/is_active")

    def active() -> bool:
        if not is_active.wait_for_service(timeout_sec=1.0):
            return False
        return bool(wait_future(is_active.call_async(Trigger.Request()), 10, "is_active").success)

    wait_until(active, timeout=90, what=logs)
    up = time.monotonic() - started
    # The world with the boxes is the one running (a later -p world:= wins).
    assert parameter(node, "/sim_world", "world") == str(world)
    navigator = ThreadSafeActionClient(node, NavigateToPose, "/navigate_to_pose")
    assert navigator.wait_for_server(timeout_sec=30)

    def send(goal: tuple[float, float, float]) -> Any:
        sent = navigator.send_goal_async(NavigateToPose.Goal(pose=pose_stamped(*goal)))
        handle = wait_future(sent, 30, "the goal was not answered")
        assert handle.accepted, "the goal was rejected"
        return handle

    # 1. Past the corridor box: its first plan runs through the box (out of sight then).
    t0 = time.monotonic()
    handle = send(EAST_GOAL)
    outcome = wait_future(handle.get_result_async(), 90, lambda: "east goal\n" + logs())
    drive = time.monotonic() - t0
    assert outcome.status == GoalStatus.STATUS_SUCCEEDED, (outcome.result, logs())
    x, y = truth.get()
    assert math.hypot(x - EAST_GOAL[0], y - EAST_GOAL[1]) < 0.3, (x, y)
    gaps = []
    for plan in plans:
        xs = [p.pose.position.x for p in plan.poses]
        ys = [p.pose.position.y for p in plan.poses]
        gaps.append(float(box_distance(CORRIDOR_BOX, xs, ys).min()))
    assert gaps[0] < RADIUS, f"the first plan should run into the unseen box: {gaps}"
    assert gaps[-1] > RADIUS, f"the last plan should go round the box: {gaps}"
    assert truth.closest > RADIUS, (
        f"the robot came {truth.closest:.3f} m from an obstacle at (x, y, speed, s) "
        f"{truth.closest_at}\n{logs()}"
    )
    wait_until(lambda: costmaps, timeout=10, what="/global_costmap/costmap")
    box_x, box_y, half, _ = CORRIDOR_BOX
    assert cost_near(costmaps[-1], box_x, box_y, half + 0.05) == 100, "the box is not lethal"

    # 2. Into the lounge through its blocked door: Nav2's error code, the robot standing.
    handle = send(LOUNGE_GOAL)
    failed = wait_future(handle.get_result_async(), 60, lambda: "lounge goal\n" + logs())
    assert failed.status == GoalStatus.STATUS_ABORTED, (failed.result, logs())
    assert failed.result.error_code == ComputePathToPose.Result.NO_VALID_PATH, failed.result
    wait_until(lambda: truth.speed < STOPPED, timeout=5, what=lambda: f"speed {truth.speed}")
    assert truth.closest > RADIUS, (
        f"the robot came {truth.closest:.3f} m from an obstacle at (x, y, speed, s) "
        f"{truth.closest_at}\n{logs()}"
    )

    # 3. West, cancelled on the way: stopped within 0.5 s of the cancel.
    handle = send(WEST_GOAL)
    wait_until(lambda: truth.speed > 0.2, timeout=30, what="the robot to drive off")
    cancel_at = time.monotonic()
    handle.cancel_goal_async()
    wait_until(lambda: truth.speed < STOPPED, timeout=5, interval=0.01, what="a stop")
    stopped = time.monotonic() - cancel_at
    cancelled = wait_future(handle.get_result_async(), 30, "the cancelled goal did not end")
    assert cancelled.status == GoalStatus.STATUS_CANCELED
    assert stopped < 0.5, f"the robot stopped {stopped:.2f} s after the cancel"
    for name in (
        "planner_server",
        "controller_server",
        "bt_navigator",
        "lifecycle_manager_navigation",
    ):
        assert supervisor.status(name).active, name
        assert "Traceback" not in "\n".join(supervisor.output(name)), logs()
    print(
        f"\nup {up:.1f} s, past the box in {drive:.1f} s (plans' gaps to the box "
        f"{gaps[0]:.2f} -> {gaps[-1]:.2f} m), closest {truth.nearest} at {truth.closest_at}, "
        f"stopped {stopped:.2f} s after the cancel, test {time.monotonic() - started:.1f} s"
    )
