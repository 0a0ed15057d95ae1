"""Small stand-ins for Nav2's servers, on Nav2's names, for testing the Simple Commander.

Real rclpy action servers and services serving the real ``nav2_msgs``
interfaces, in a node of their own with its own rclpy context, spun by a
multi-threaded executor in a thread: the navigator under test talks to them
over DDS exactly as it would to Nav2. Each remembers what it was sent. Imports
only rclpy and ROS messages.
"""

from __future__ import annotations

import threading
import time
from collections import defaultdict
from functools import partial
from typing import Any

import rclpy
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
from lifecycle_msgs.msg import State
from lifecycle_msgs.srv import GetState
from nav2_msgs.action import (
    BackUp,
    ComputePathToPose,
    DriveOnHeading,
    FollowPath,
    FollowWaypoints,
    NavigateThroughPoses,
    NavigateToPose,
    Spin,
)
from nav2_msgs.srv import ClearEntireCostmap, GetCostmap, LoadMap, ManageLifecycleNodes
from nav_msgs.msg import Path
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.context import Context
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
ACTIONS = {
    "navigate_to_pose": NavigateToPose,
    "navigate_through_poses": NavigateThroughPoses,
    "follow_waypoints": FollowWaypoints,
    "follow_path": FollowPath,
    "spin": Spin,
    "backup": BackUp,
    "drive_on_heading": DriveOnHeading,
}
MANAGERS = ("lifecycle_manager_localization", "lifecycle_manager_navigation")
SUCCEED, ABORT, UNTIL_CANCELED = "succeed", "abort", "until_canceled"
LABELS = {State.PRIMARY_STATE_INACTIVE: "inactive", State.PRIMARY_STATE_ACTIVE: "active"}


def wait_for(predicate: Any, timeout: float, what: str) -> Any:
    deadline = time.monotonic() + timeout
    while not (value := predicate()):
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")
        time.sleep(0.05)
    return value


def straight_path(start: PoseStamped, goal: PoseStamped, steps: int = 5) -> Path:
    path = Path()
    path.header.frame_id = "map"
    for i in range(steps + 1):
        pose = PoseStamped()
        pose.header.frame_id = "map"
        s = i / steps
        pose.pose.position.x = start.pose.position.x + s * (
            goal.pose.position.x - start.pose.position.x
        )
        pose.pose.position.y = start.pose.position.y + s * (
            goal.pose.position.y - start.pose.position.y
        )
        pose.pose.orientation.w = 1.0
        path.poses.append(pose)
    return path


class FakeNav2:
    """Nav2's action servers and services, each answering as a test sets it up.

    ``mode[action]`` is ``succeed`` (a few feedback messages, then success),
    ``abort`` or ``until_canceled``; ``navigate_to_pose`` rejects a goal with a
    negative x (off this pretend map), ``compute_path_to_pose`` aborts one.
    ``states`` holds each lifecycle node's state; amcl answers an initial pose
    with ``amcl_pose`` while active, as amcl does.
    """

    def __init__(self) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = Node("fake_nav2", context=self.context)
        self.mode: dict[str, str] = defaultdict(lambda: SUCCEED)
        self.goals: dict[str, list[Any]] = defaultdict(list)
        self.calls: dict[str, list[Any]] = defaultdict(list)
        self.canceled: list[str] = []
        self.initial_poses: list[PoseWithCovarianceStamped] = []
        self.states = {
            "amcl": State.PRIMARY_STATE_ACTIVE,
            "bt_navigator": State.PRIMARY_STATE_ACTIVE,
        }
        self.planned: list[Path] = []
        self._stop = threading.Event()
        group = ReentrantCallbackGroup()
        self._servers = [
            ActionServer(
                self.node,
                action_type,
                name,
                execute_callback=lambda handle, name=name: self._execute(name, handle),
                goal_callback=lambda goal, name=name: self._on_goal(name, goal),
                cancel_callback=lambda _handle, name=name: self._on_cancel(name),
                callback_group=group,
            )
            for name, action_type in ACTIONS.items()
        ]
        self._servers.append(
            ActionServer(
                self.node,
                ComputePathToPose,
                "compute_path_to_pose",
                execute_callback=self._plan,
                callback_group=group,
            )
        )
        srv = self.node.create_service
        for costmap in ("global_costmap", "local_costmap"):
            srv(
                ClearEntireCostmap,
                f"{costmap}/clear_entirely_{costmap}",
                partial(self._record, f"clear {costmap}"),
                callback_group=group,
            )
            srv(
                GetCostmap,
                f"{costmap}/get_costmap",
                partial(self._costmap, costmap),
                callback_group=group,
            )
        srv(LoadMap, "map_server/load_map", self._load_map, callback_group=group)
        for lifecycle_node in self.states:
            srv(
                GetState,
                f"{lifecycle_node}/get_state",
                partial(self._get_state, lifecycle_node),
                callback_group=group,
            )
        for manager in MANAGERS:
            srv(
                ManageLifecycleNodes,
                f"{manager}/manage_nodes",
                partial(self._manage, manager),
                callback_group=group,
            )
        self.amcl_pose_pub = self.node.create_publisher(
            PoseWithCovarianceStamped, "amcl_pose", LATCHED
        )
        self.node.create_subscription(
            PoseWithCovarianceStamped,
            "initialpose",
            self._on_initial_pose,
            10,
            callback_group=group,
        )
        self.executor = MultiThreadedExecutor(num_threads=4, context=self.context)
        self.executor.add_node(self.node)
        self._thread = threading.Thread(target=self.executor.spin, daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        self.executor.shutdown(timeout_sec=5.0)
        self._thread.join(timeout=10.0)
        for server in self._servers:
            server.destroy()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        assert not self._thread.is_alive(), "the fake servers' executor did not stop"

    # -- actions --------------------------------------------------------------------------

    def _on_goal(self, name: str, goal: Any) -> GoalResponse:
        self.goals[name].append(goal)
        if name == "navigate_to_pose" and goal.pose.pose.position.x < 0:
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def _on_cancel(self, name: str) -> CancelResponse:
        self.canceled.append(name)
        return CancelResponse.ACCEPT

    def _feedback(self, name: str, step: int) -> Any:
        feedback = ACTIONS[name].Feedback()
        if name in ("navigate_to_pose", "navigate_through_poses"):
            feedback.distance_remaining = 10.0 - step
            feedback.current_pose.pose.position.x = float(step)
            feedback.navigation_time.sec = step
        elif name == "follow_waypoints":
            feedback.current_waypoint = step
        elif name == "follow_path":
            feedback.distance_to_goal = 10.0 - step
        elif name == "spin":
            feedback.angular_distance_traveled = 0.1 * step
        else:
            feedback.distance_traveled = 0.01 * step
        return feedback

    def _execute(self, name: str, handle: Any) -> Any:
        mode = self.mode[name]
        step = 0
        while not self._stop.is_set():
            if handle.is_cancel_requested:
                handle.canceled()
                return ACTIONS[name].Result()
            handle.publish_feedback(self._feedback(name, step))
            step += 1
            if mode != UNTIL_CANCELED and step >= 5:
                break
            time.sleep(0.1)
        result = ACTIONS[name].Result()
        if mode == SUCCEED and not self._stop.is_set():
            handle.succeed()
        else:
            result.error_code = 1
            result.error_msg = "told to fail"
            handle.abort()
        return result

    def _plan(self, handle: Any) -> ComputePathToPose.Result:
        request = handle.request
        self.goals["compute_path_to_pose"].append(request)
        result = ComputePathToPose.Result()
        if request.goal.pose.position.x < 0:
            result.error_code = ComputePathToPose.Result.GOAL_OUTSIDE_MAP
            result.error_msg = "goal outside the map"
            handle.abort()
            return result
        result.path = straight_path(request.start, request.goal)
        self.planned.append(result.path)
        handle.succeed()
        return result

    # -- services and topics --------------------------------------------------------------

    def _record(self, what: str, request: Any, response: Any) -> Any:
        self.calls[what].append(request)
        return response

    def _costmap(
        self, costmap: str, _request: GetCostmap.Request, response: GetCostmap.Response
    ) -> GetCostmap.Response:
        self.calls[f"get {costmap}"].append(True)
        response.map.header.frame_id = "map" if costmap == "global_costmap" else "odom"
        response.map.metadata.size_x = 3
        response.map.metadata.size_y = 2
        response.map.metadata.resolution = 0.05
        response.map.data = [0, 0, 254, 0, 253, 255]
        return response

    def _load_map(self, request: LoadMap.Request, response: LoadMap.Response) -> LoadMap.Response:
        self.calls["load_map"].append(request.map_url)
        if request.map_url.endswith(".yaml"):
            response.result = LoadMap.Response.RESULT_SUCCESS
        else:
            response.result = LoadMap.Response.RESULT_MAP_DOES_NOT_EXIST
        return response

    def _get_state(
        self, node: str, _request: GetState.Request, response: GetState.Response
    ) -> GetState.Response:
        state = self.states[node]
        response.current_state.id = state
        response.current_state.label = LABELS.get(state, "unconfigured")
        return response

    def _manage(
        self, manager: str, request: ManageLifecycleNodes.Request, response: Any
    ) -> ManageLifecycleNodes.Response:
        self.calls[manager].append(request.command)
        if request.command == ManageLifecycleNodes.Request.STARTUP:
            for node in self.states:
                self.states[node] = State.PRIMARY_STATE_ACTIVE
        elif request.command == ManageLifecycleNodes.Request.SHUTDOWN:
            for node in self.states:
                self.states[node] = State.PRIMARY_STATE_FINALIZED
        response.success = True
        return response

    def _on_initial_pose(self, msg: PoseWithCovarianceStamped) -> None:
        self.initial_poses.append(msg)
        if self.states["amcl"] == State.PRIMARY_STATE_ACTIVE:
            pose = PoseWithCovarianceStamped()
            pose.header.frame_id = "map"
            pose.pose = msg.pose
            self.amcl_pose_pub.publish(pose)
