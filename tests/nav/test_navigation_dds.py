"""Nav2's planner, controller, navigator and lifecycle manager over real DDS, in the office.

sim_world (office, faster than real time, world -> odom on /tf), a static
``map -> world`` identity from the test (no AMCL here), map_server with the
office map, planner_server, controller_server and bt_navigator, brought up
by one lifecycle_manager (autostart). An ActionClient sends NavigateToPose
goals as ``ros2 action send_goal`` or BasicNavigator would (the thread-safe
one: this test sends from its own thread while the probe's executor takes
the answers, the rclpy 7.1.6 race tests/integration/test_action_client_race.py
shows; a result answer lost to it once left "the wall goal did not end"):
from the corridor into the meeting room through its door (reached, feedback
with a shrinking distance_remaining, never near a wall by ground truth),
into a wall (an error code, the servers live on), and one that is cancelled
(the robot stops). The planner keeps a finished goal on its action server for
``action_server_result_timeout`` seconds, as Nav2's does (rclpy's own
default would keep it 15 minutes, and every status message would list it).
"""

from __future__ import annotations

import math
import threading
import time
from typing import Any

import numpy as np
import pytest
from action_msgs.msg import GoalStatus, GoalStatusArray
from geometry_msgs.msg import TransformStamped
from nav2_msgs.action import ComputePathToPose, NavigateToPose
from nav_msgs.msg import Odometry, Path
from rclpy.action import ActionClient
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_srvs.srv import Trigger
from tf2_msgs.msg import TFMessage

from app import PROJECT_ROOT
from app.catalog import lookup
from app.lessons.checks._world_map import load_world_map
from app.ros.action_client import ThreadSafeActionClient
from nodes.common.occupancy_grid import plan_distance
from tests.conftest import wait_until
from tests.nav.goal_helpers import parameter, pose_stamped, wait_future

pytestmark = [pytest.mark.ros, pytest.mark.timeout(240)]

LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
SIM_ARGS = ("-p", "camera_rate:=0.0", "-p", "real_time_factor:=2.0")
MAP_YAML = PROJECT_ROOT / "nodes" / "worlds" / "office" / "map.yaml"
MANAGED = ["map_server", "planner_server", "controller_server", "bt_navigator"]
DOOR_GOAL = (4.0, 1.7, math.pi / 2)  # the meeting room, through its door at x = 3.7..4.6
WALL_GOAL = (0.6, 0.8, 0.0)  # on the corridor's north wall
FAR_GOAL = (-3.0, 2.0, 0.0)  # the office, west: long enough to cancel on the way
RESULT_KEPT = 2.0  # s: the planner's action_server_result_timeout here (Nav2's default: 10)


class Truth:
    """The robot's true pose, its speed and its closest approach to the floor plan."""

    def __init__(self, node: Any) -> None:
        self.lock = threading.Lock()
        self.pose: tuple[float, float, float] | None = None
        self.speed = 0.0
        self.closest = math.inf
        self.obstacles = load_world_map("office").obstacles
        node.create_subscription(Odometry, "/ground_truth/odom", self.on_truth, 10)

    def on_truth(self, msg: Odometry) -> None:
        p = msg.pose.pose.position
        distance = float(plan_distance(self.obstacles, np.array([p.x]), np.array([p.y]))[0])
        tw = msg.twist.twist
        with self.lock:
            self.pose = (p.x, p.y, time.monotonic())
            self.speed = math.hypot(tw.linear.x, tw.linear.y)
            self.closest = min(self.closest, distance)

    def get(self) -> tuple[float, float, float]:
        wait_until(lambda: self.pose, timeout=60, what="/ground_truth/odom")
        with self.lock:
            assert self.pose is not None
            return self.pose


def send(client: ActionClient, goal: Any, feedback: list[Any]) -> Any:
    handle = wait_future(
        client.send_goal_async(goal, feedback_callback=lambda f: feedback.append(f.feedback)),
        30,
        "the goal was not answered",
    )
    assert handle.accepted, "the goal was rejected"
    return handle


def map_to_world(node: Any) -> Any:
    publisher = node.create_publisher(TFMessage, "/tf_static", LATCHED)
    tf = TransformStamped()
    tf.header.frame_id, tf.child_frame_id = "map", "world"
    tf.transform.rotation.w = 1.0
    publisher.publish(TFMessage(transforms=[tf]))
    return publisher


def test_navigate_to_pose_through_a_door_a_wall_goal_and_a_cancel(probe, supervisor):
    started = time.monotonic()
    node = probe.node
    truth = Truth(node)
    static_pub = map_to_world(node)
    plans: list[Path] = []
    node.create_subscription(Path, "/plan", plans.append, 10)
    supervisor.start_program(lookup("sim_office"), SIM_ARGS)
    supervisor.start_program(lookup("map_server"), ("-p", f"yaml_filename:={MAP_YAML}"))
    supervisor.start_program(
        lookup("planner_server"),
        ("-p", "GridBased.tolerance:=0.0", "-p", f"action_server_result_timeout:={RESULT_KEPT}"),
    )
    supervisor.start_program(lookup("controller_server"))
    supervisor.start_program(lookup("bt_navigator"))
    # The catalog's manager also brings up amcl; this test has no amcl (a static map -> world).
    supervisor.start_program(
        lookup("lifecycle_manager_navigation"),
        ("-p", f"node_names:=[{','.join(MANAGED)}]"),
    )
    truth.get()

    is_active = node.create_client(Trigger, "/lifecycle_manager_navigation/is_active")

    def active() -> bool:
        if not is_active.wait_for_service(timeout_sec=1.0):
            return False
        return bool(wait_future(is_active.call_async(Trigger.Request()), 10, "is_active").success)

    wait_until(active, timeout=90, what=lambda: _logs(supervisor))
    up = time.monotonic() - started

    # The planner alone: a path from the robot into the meeting room, on /plan.
    planner = ThreadSafeActionClient(node, ComputePathToPose, "/compute_path_to_pose")
    assert planner.wait_for_server(timeout_sec=30)
    plan_goal = ComputePathToPose.Goal(goal=pose_stamped(*DOOR_GOAL))
    plan_handle = send(planner, plan_goal, [])
    planned = wait_future(plan_handle.get_result_async(), 30, "no plan")
    assert planned.status == GoalStatus.STATUS_SUCCEEDED, planned.result.error_msg
    assert len(planned.result.path.poses) > 20
    planning_ms = (
        planned.result.planning_time.nanosec / 1e6 + planned.result.planning_time.sec * 1e3
    )
    wait_until(lambda: plans, timeout=20, what="/plan")

    # Once its result timeout has passed, a finished plan is gone from the action's status
    # list: the next plan's status lists that one alone. Nav2's controller keeps results 10 s.
    statuses: list[GoalStatusArray] = []
    node.create_subscription(
        GoalStatusArray, "/compute_path_to_pose/_action/status", statuses.append, LATCHED
    )
    time.sleep(RESULT_KEPT + 1.0)
    second = send(planner, plan_goal, [])
    assert wait_future(second.get_result_async(), 30, "no second plan").status == (
        GoalStatus.STATUS_SUCCEEDED
    )

    def listed() -> list[bytes]:
        return [bytes(s.goal_info.goal_id.uuid) for s in statuses[-1].status_list]

    wait_until(
        lambda: statuses and bytes(second.goal_id.uuid) in listed(),
        timeout=10,
        what="the second plan in the status list",
    )
    assert bytes(plan_handle.goal_id.uuid) not in listed(), "an expired plan is still listed"
    assert parameter(node, "/controller_server", "action_server_result_timeout") == 10.0

    # Navigate into the meeting room.
    navigator = ThreadSafeActionClient(node, NavigateToPose, "/navigate_to_pose")
    assert navigator.wait_for_server(timeout_sec=30)
    feedback: list[Any] = []
    t0 = time.monotonic()
    handle = send(navigator, NavigateToPose.Goal(pose=pose_stamped(*DOOR_GOAL)), feedback)
    outcome = wait_future(handle.get_result_async(), 120, "the navigation did not end")
    drive = time.monotonic() - t0
    assert outcome.status == GoalStatus.STATUS_SUCCEEDED, (
        outcome.result.error_code,
        outcome.result.error_msg,
        _logs(supervisor),
    )
    x, y, _ = truth.get()
    assert math.hypot(x - DOOR_GOAL[0], y - DOOR_GOAL[1]) < 0.3, (x, y)
    distances = [f.distance_remaining for f in feedback if f.distance_remaining > 0]
    # Feedback comes with each plan and control step; a loaded machine may skip the last metres.
    assert len(distances) > 5 and distances[0] > 3.0 and distances[-1] < distances[0] - 2.0, (
        distances
    )
    assert truth.closest > 0.12, f"the robot came {truth.closest:.3f} m from an obstacle"

    # A goal inside a wall: an error code and a sentence, and the servers live on.
    handle = send(navigator, NavigateToPose.Goal(pose=pose_stamped(*WALL_GOAL)), [])
    failed = wait_future(handle.get_result_async(), 60, "the wall goal did not end")
    assert failed.status == GoalStatus.STATUS_ABORTED
    assert failed.result.error_code == ComputePathToPose.Result.GOAL_OCCUPIED, failed.result
    assert "lethal" in failed.result.error_msg

    # Cancel on the way: the goal ends canceled and the robot stops.
    feedback = []
    handle = send(navigator, NavigateToPose.Goal(pose=pose_stamped(*FAR_GOAL)), feedback)
    wait_until(lambda: truth.speed > 0.1, timeout=30, what="the robot to drive off")
    cancel_at = time.monotonic()
    wait_future(handle.cancel_goal_async(), 10, "the cancel was not answered")
    cancelled = wait_future(handle.get_result_async(), 30, "the cancelled goal did not end")
    assert cancelled.status == GoalStatus.STATUS_CANCELED
    wait_until(lambda: truth.speed < 0.02, timeout=5, what=lambda: f"speed {truth.speed}")
    stopped = time.monotonic() - cancel_at
    for name in (
        "planner_server",
        "controller_server",
        "bt_navigator",
        "lifecycle_manager_navigation",
    ):
        assert supervisor.status(name).active, name
        assert "Traceback" not in "\n".join(supervisor.output(name)), _logs(supervisor)
    # Kept to the end: its latched map -> world is what a late listener still needs (an
    # empty message published "to keep it referenced" replaced that sample, and a
    # bt_navigator whose listener matched after it never had map: feedback without a pose).
    node.destroy_publisher(static_pub)
    print(
        f"\nnav up {up:.1f} s, plan {planning_ms:.0f} ms, drive {drive:.1f} s wall, "
        f"closest {truth.closest:.3f} m, stopped {stopped:.2f} s after cancel, "
        f"test {time.monotonic() - started:.1f} s"
    )


def _logs(supervisor: Any) -> str:
    names = ("sim_office", "map_server", "planner_server", "controller_server", "bt_navigator",
             "lifecycle_manager_navigation")  # fmt: skip
    return "\n".join(f"--- {n}\n" + "\n".join(supervisor.output(n, last=30)) for n in names)
