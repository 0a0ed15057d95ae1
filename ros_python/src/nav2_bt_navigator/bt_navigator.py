"""bt_navigator: Nav2's navigator: ``navigate_to_pose`` and ``navigate_through_poses``.

Nav2's bt_navigator runs a behaviour tree (``navigate_to_pose_w_replanning_and_recovery.xml``);
this one runs the same steps as plain code, no behaviour tree (nor its XML,
``behavior_tree`` in the goal is ignored):

1. plan with the planner server's ``compute_path_to_pose`` (``planner_id``
   ``GridBased``) from the robot to the goal, and again about once a second
   (``replanning_period``, the tree's RateController at 1 Hz) while driving;
2. follow each new path with the controller server's ``follow_path``
   (``controller_id`` ``FollowPath``);
3. when following fails (the controller saw a collision ahead, or made no
   progress), count a recovery (``number_of_recoveries``), run the next of
   the recovery actions in turn (the tree's RoundRobin), plan again and carry
   on, at most ``number_of_retries`` (6) times, as the tree's RecoveryNode;
   then the goal ends aborted with the failing server's error code and
   message (e.g. ComputePathToPose's ``GOAL_OCCUPIED`` 206, FollowPath's
   ``FAILED_TO_MAKE_PROGRESS`` 105). A first plan that fails ends the goal
   (``NO_VALID_PATH`` 208 when an obstacle the scans saw closes the way), and
   so do three replans in a row that fail. Each plan is one try as the tree's
   ComputePathToPose RecoveryNode makes it: a plan that fails with a code a
   planner recovery may help with (``NO_VALID_PATH``, ``TIMEOUT``,
   ``UNKNOWN``) clears the global costmap (a scan taken while the robot's
   pose was off may have drawn a wall across a door), waits
   ``recovery_wait`` for its next update and plans once more; other codes,
   e.g. ``GOAL_OCCUPIED``, fail at once.

The recovery actions, in turn: *wait* ``recovery_wait`` (1 s: the costmaps
take in what the scans show, so the next plan goes round a new obstacle);
*back up* ``backup_dist`` (0.30 m) at ``backup_speed`` (0.15 m/s) on
``cmd_vel``, as Nav2's BackUp behavior, unless the local costmap
(``/local_costmap/costmap``) shows an obstacle behind; *clear* both costmaps'
obstacle layers (``clear_entirely_*``: what was seen may be gone). Nav2 runs
its behaviors (spin, wait, back up) in a behavior server; this navigator does
these three itself and has no spin, and waits first where the tree clears
first: a cleared costmap would forget the very obstacle the controller just
stopped for.

Feedback as Nav2 sends it: ``current_pose`` (TF ``map -> base_link``),
``navigation_time``, ``estimated_time_remaining`` (distance over speed),
``number_of_recoveries``, ``distance_remaining`` (along the path), and
``number_of_poses_remaining`` for ``navigate_through_poses`` (a pose counts
as passed within 0.5 m, as RemovePassedGoals). Cancelling stops the
controller, hence the robot: the cancel is passed on to the controller the
moment it arrives. A new goal preempts the running one.
"""

from __future__ import annotations

import math
import sys
import threading
import time
from typing import Any

from geometry_msgs.msg import PoseStamped, Twist
from lifecycle_msgs.msg import State
from nav2_costmap_2d.costmap_2d_ros import LATCHED, own_listener, stop_listener, yaw_of
from nav2_msgs.action import ComputePathToPose, FollowPath, NavigateThroughPoses, NavigateToPose
from nav2_msgs.srv import ClearEntireCostmap
from nav2_util.action_client import SerializedActionClient
from nav2_util.lifecycle_node import LifecycleNode
from nav2_util.server_main import spin_server
from nav_msgs.msg import OccupancyGrid, Path
from rclpy.action import ActionClient, ActionServer, CancelResponse, GoalResponse
from rclpy.action.client import ClientGoalHandle
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.duration import Duration
from rclpy.lifecycle import LifecycleState, TransitionCallbackReturn
from rclpy.task import Future
from rclpy.time import Time
from tf2_ros.buffer import Buffer

SUCCEEDED, CANCELED, ABORTED = 4, 5, 6  # action_msgs/GoalStatus
FINAL_STATUSES = (SUCCEEDED, CANCELED, ABORTED)
RECOVERIES = ("wait", "back up", "clear costmaps")  # in turn, as the tree's RoundRobin
LETHAL = 100  # an obstacle on a published costmap (OccupancyGrid values)
# ComputePathToPose's codes a planner recovery may help with (Nav2's WouldAPlannerRecoveryHelp)
PLANNER_RETRY = (
    ComputePathToPose.Result.UNKNOWN,
    ComputePathToPose.Result.NO_VALID_PATH,
    ComputePathToPose.Result.TIMEOUT,
)
LOCAL_COSTMAP = "local_costmap/clear_entirely_local_costmap"
GLOBAL_COSTMAP = "global_costmap/clear_entirely_global_costmap"
COSTMAPS = (LOCAL_COSTMAP, GLOBAL_COSTMAP)


class NavigationFailed(Exception):
    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


class Preempted(Exception):
    pass


def wait_for(future: Future, timeout: float, stop: Any = None) -> bool:
    """Wait (from an execute thread) for a future; False on timeout or when ``stop()``."""
    done = threading.Event()
    future.add_done_callback(lambda _f: done.set())
    deadline = time.monotonic() + timeout
    while not done.wait(0.02):
        if time.monotonic() > deadline or (stop is not None and stop()):
            return False
    return True


def remaining_length(path: list[tuple[float, float]], pose: tuple[float, float, float]) -> float:
    if not path:
        return 0.0
    best = min(
        range(len(path)), key=lambda i: math.hypot(path[i][0] - pose[0], path[i][1] - pose[1])
    )
    length = math.hypot(path[best][0] - pose[0], path[best][1] - pose[1])
    for a, b in zip(path[best:], path[best + 1 :], strict=False):
        length += math.hypot(b[0] - a[0], b[1] - a[1])
    return length


class BtNavigator(LifecycleNode):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__("bt_navigator", **kwargs)
        self.get_logger().info("Creating")
        p = self.declare_parameter
        p("global_frame", "map")
        p("robot_base_frame", "base_link")
        p("transform_tolerance", 0.1)
        p("odom_topic", "odom")  # Nav2's, for its odometry smoother; speed comes from FollowPath
        p("replanning_period", 1.0)
        p("number_of_retries", 6)
        p("planner_id", "GridBased")
        p("controller_id", "FollowPath")
        p("goal_reached_tol", 0.5)  # RemovePassedGoals' radius for navigate_through_poses
        p("recovery_wait", 1.0)
        p("backup_dist", 0.30)  # the tree's BackUp
        p("backup_speed", 0.15)
        p("robot_radius", 0.15)  # the costmaps' robot_radius: the room backing up needs
        p("local_costmap_topic", "local_costmap/costmap")
        p("action_server_result_timeout", 900.0)  # Nav2's bt_action_server default
        self.group = ReentrantCallbackGroup()
        self.lock = threading.Lock()
        self.current: Any = None
        self.following: Any = None  # the running follow_path goal, for a cancel to reach it
        self.speed = 0.0
        self.local_costmap: OccupancyGrid | None = None
        self.cmd_vel: Any = None
        self.costmap_sub: Any = None
        self.clear_clients: list[Any] = []
        self.servers: list[ActionServer] = []
        self.action_clients: list[ActionClient] = []
        self.tf_buffer = Buffer(node=self)
        # As Nav2's C++ listener: a node and a thread of its own (transform_listener_impl_*).
        # /tf comes at 60-80 messages a wall second with the world at twice real time; each
        # one through this node's multi-threaded executor cost a wake-up of its whole wait
        # set (about a third of the process's CPU), through a one-node executor very little.
        self.tf_listener = own_listener(self.tf_buffer)

    # --- transitions ---
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Configuring")
        g = self.get_parameter
        self.global_frame = str(g("global_frame").value)
        self.robot_base_frame = str(g("robot_base_frame").value)
        self.planner = SerializedActionClient(
            self, ComputePathToPose, "compute_path_to_pose", callback_group=self.group
        )
        self.controller = SerializedActionClient(
            self, FollowPath, "follow_path", callback_group=self.group
        )
        self.action_clients = [self.planner, self.controller]
        self.cmd_vel = self.create_lifecycle_publisher(Twist, "cmd_vel", 1)
        self.costmap_sub = self.create_subscription(
            OccupancyGrid,
            str(g("local_costmap_topic").value),
            self.on_local_costmap,
            LATCHED,
            callback_group=self.group,
        )
        self.clear_clients = [
            self.create_client(ClearEntireCostmap, name, callback_group=self.group)
            for name in COSTMAPS
        ]
        for action_type, name, execute in (
            (NavigateToPose, "navigate_to_pose", self.navigate_to_pose),
            (NavigateThroughPoses, "navigate_through_poses", self.navigate_through_poses),
        ):
            self.servers.append(
                ActionServer(
                    self,
                    action_type,
                    name,
                    execute_callback=execute,
                    goal_callback=self.on_goal,
                    handle_accepted_callback=self.on_accepted,
                    cancel_callback=self.on_cancel,
                    callback_group=self.group,
                    result_timeout=float(self.get_parameter("action_server_result_timeout").value),
                )
            )
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Activating")
        return super().on_activate(state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Deactivating")
        with self.lock:
            self.current = None
        return super().on_deactivate(state)

    def release(self) -> None:
        with self.lock:
            self.current = None
        for server in self.servers:
            server.destroy()
        for client in self.action_clients:
            client.destroy()
        self.servers, self.action_clients = [], []
        for client in self.clear_clients:
            self.destroy_client(client)
        self.clear_clients = []
        if self.costmap_sub is not None:
            self.destroy_subscription(self.costmap_sub)
            self.costmap_sub = None
        self.local_costmap = None
        if self.cmd_vel is not None:
            self.destroy_lifecycle_publisher(self.cmd_vel)
            self.cmd_vel = None

    def active(self) -> bool:
        return self._state_machine.current_state[0] == State.PRIMARY_STATE_ACTIVE

    def on_follow_feedback(self, message: Any) -> None:
        # The controller's odometry speed: no /odom subscription of our own (60 messages a
        # second with the world at twice real time, each a wake-up of this node's executor).
        self.speed = abs(float(message.feedback.speed))

    def on_local_costmap(self, msg: OccupancyGrid) -> None:
        self.local_costmap = msg

    def robot_pose(self) -> tuple[float, float, float] | None:
        try:
            tf = self.tf_buffer.lookup_transform(
                self.global_frame,
                self.robot_base_frame,
                Time(),
                Duration(seconds=float(self.get_parameter("transform_tolerance").value) + 0.4),
            )
        except Exception as exc:
            self.get_logger().error(f"Could not get robot pose: {exc}", throttle_duration_sec=2.0)
            return None
        t = tf.transform.translation
        return (t.x, t.y, yaw_of(tf.transform.rotation))

    # --- the actions ---
    def on_goal(self, goal: Any) -> GoalResponse:
        if not self.active():
            self.get_logger().warning("Action server is inactive. Rejecting the goal.")
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def on_accepted(self, handle: Any) -> None:
        with self.lock:
            previous, self.current = self.current, handle
        if previous is not None:
            self.get_logger().info("Received goal preemption request")
        handle.execute()

    def on_cancel(self, handle: Any) -> CancelResponse:
        # Stop the robot now: the navigation loop only looks every 0.1 s, and a plan it may
        # be waiting for takes longer still.
        with self.lock:
            following = self.following if handle is self.current else None
        if following is not None:
            following.handle.cancel_goal_async()
        return CancelResponse.ACCEPT

    def finished(self, handle: Any) -> None:
        """The goal ended: no longer the current one (a next goal is no preemption)."""
        with self.lock:
            if self.current is handle:
                self.current = None
                self.following = None

    def navigate_to_pose(self, handle: Any) -> Any:
        goal = handle.request.pose
        return self.navigate(handle, [goal], NavigateToPose)

    def navigate_through_poses(self, handle: Any) -> Any:
        return self.navigate(handle, list(handle.request.poses), NavigateThroughPoses)

    def navigate(self, handle: Any, goals: list[PoseStamped], action: Any) -> Any:
        try:
            return self._navigate(handle, goals, action)
        finally:
            self.finished(handle)

    def _navigate(self, handle: Any, goals: list[PoseStamped], action: Any) -> Any:
        result = action.Result()
        started = time.monotonic()
        through = action is NavigateThroughPoses
        if not goals:
            result.error_code, result.error_msg = 0, "No poses to navigate through"
            self.get_logger().error(result.error_msg)
            handle.abort()
            return result
        pose = self.robot_pose()
        where = f"({pose[0]:.2f}, {pose[1]:.2f})" if pose else "(unknown)"
        last = goals[-1].pose.position
        if through:
            self.get_logger().info(
                f"Begin navigating from current location {where} using {len(goals)} poses"
            )
        else:
            self.get_logger().info(
                f"Begin navigating from current location {where} to ({last.x:.2f}, {last.y:.2f})"
            )
        state: dict[str, Any] = {"follow": None, "path": [], "recoveries": 0}

        def stop() -> bool:
            return handle.is_cancel_requested or handle is not self.current

        try:
            period = float(self.get_parameter("replanning_period").value)
            retries = int(self.get_parameter("number_of_retries").value)
            path = self.plan_with_recovery(goals, stop)
            follow = self.follow(path, stop, handle)
            state["path"] = [(p.pose.position.x, p.pose.position.y) for p in path.poses]
            last_plan = time.monotonic()
            failures = 0
            while True:
                if handle.is_cancel_requested:
                    self.cancel_follow(follow)
                    self.get_logger().info("Goal was canceled. Stopping the robot.")
                    handle.canceled()
                    return result
                if handle is not self.current:
                    raise Preempted()
                if follow is not None and follow.done():
                    outcome = follow.result()
                    if outcome is not None and outcome.status == SUCCEEDED:
                        self.get_logger().info("Goal succeeded")
                        handle.succeed()
                        return result
                    code = outcome.result.error_code if outcome is not None else 0
                    message = outcome.result.error_msg if outcome is not None else ""
                    if state["recoveries"] >= retries:
                        raise NavigationFailed(code, message or "Following the path failed")
                    recovery = RECOVERIES[state["recoveries"] % len(RECOVERIES)]
                    state["recoveries"] += 1
                    self.get_logger().warning(
                        f"Following the path failed ({code}: {message}); "
                        f"recovery {state['recoveries']} of {retries}: {recovery}, then planning "
                        "again"
                    )
                    self.recover(recovery, stop)
                    last_plan = 0.0
                    follow = None
                    continue
                pose = self.robot_pose()
                if through and pose is not None:
                    tol = float(self.get_parameter("goal_reached_tol").value)
                    while (
                        len(goals) > 1
                        and math.hypot(
                            goals[0].pose.position.x - pose[0], goals[0].pose.position.y - pose[1]
                        )
                        < tol
                    ):
                        goals = goals[1:]
                if follow is None or time.monotonic() - last_plan >= period:
                    last_plan = time.monotonic()
                    try:
                        path = self.plan_with_recovery(goals, stop)
                        failures = 0
                        if follow is not None and not follow.running():
                            # It ended while the planner worked: the loop's top reads how (a
                            # new path now would throw a success away, as Nav2's tree only
                            # updates a goal that is still executing).
                            continue
                        follow = self.follow(path, stop, handle)
                        state["path"] = [(p.pose.position.x, p.pose.position.y) for p in path.poses]
                    except NavigationFailed:
                        failures += 1
                        if follow is None or failures >= 3:
                            self.cancel_follow(follow)
                            raise
                self.send_feedback(handle, action, pose, started, state, goals)
                time.sleep(0.1)
        except Preempted:
            handle.abort()
            return result
        except NavigationFailed as exc:
            if handle.is_cancel_requested:
                self.get_logger().info("Goal was canceled. Stopping the robot.")
                handle.canceled()
                return result
            if handle is not self.current:
                handle.abort()
                return result
            self.get_logger().error(f"Goal failed: {exc} (error code {exc.code})")
            result.error_code = int(exc.code)
            result.error_msg = str(exc)
            handle.abort()
            return result

    # --- recovery actions ---
    def recover(self, action: str, stop: Any) -> None:
        if action == "wait":
            deadline = time.monotonic() + float(self.get_parameter("recovery_wait").value)
            while time.monotonic() < deadline and not stop():
                time.sleep(0.05)
        elif action == "back up":
            self.back_up(stop)
        else:
            self.clear_costmaps(stop, COSTMAPS)

    def clear_costmaps(self, stop: Any, which: tuple[str, ...]) -> None:
        """Empty the obstacle layers of the costmaps named in ``which`` (of ``COSTMAPS``)."""
        # Not strict: after a deactivation there are no clients (a goal may still be ending).
        for name, client in zip(COSTMAPS, self.clear_clients, strict=False):
            if name in which and client.wait_for_service(timeout_sec=1.0):
                wait_for(client.call_async(ClearEntireCostmap.Request()), 5.0, stop)

    def back_up(self, stop: Any) -> None:
        """Drive backwards ``backup_dist`` at ``backup_speed`` while the costmap has room."""
        distance = abs(float(self.get_parameter("backup_dist").value))
        speed = abs(float(self.get_parameter("backup_speed").value))
        start = self.robot_pose()
        if start is None or speed <= 0.0 or self.cmd_vel is None:
            return
        deadline = time.monotonic() + distance / speed + 2.0
        backwards = Twist()
        backwards.linear.x = -speed
        try:
            while not stop() and time.monotonic() < deadline:
                pose = self.robot_pose()
                if pose is None or math.dist(pose[:2], start[:2]) >= distance:
                    break
                if not self.room_behind(pose):
                    self.get_logger().warning("Backing up stopped: an obstacle behind the robot")
                    break
                self.cmd_vel.publish(backwards)
                time.sleep(0.05)
        finally:
            self.cmd_vel.publish(Twist())

    def room_behind(self, pose: tuple[float, float, float]) -> bool:
        """No lethal cell of the local costmap where the robot's back will be 5 cm on."""
        grid = self.local_costmap
        if grid is None:
            return False  # blind: do not back into what may be there
        info = grid.info
        reach = float(self.get_parameter("robot_radius").value) + 0.05
        back = pose[2] + math.pi
        for turn in (-1.0, -0.5, 0.0, 0.5, 1.0):  # the rear arc, +-57 degrees
            x = pose[0] + reach * math.cos(back + turn)
            y = pose[1] + reach * math.sin(back + turn)
            mx = int((x - info.origin.position.x) / info.resolution)
            my = int((y - info.origin.position.y) / info.resolution)
            if not (0 <= mx < info.width and 0 <= my < info.height):
                return False
            if grid.data[my * info.width + mx] >= LETHAL:
                return False
        return True

    def send_feedback(
        self,
        handle: Any,
        action: Any,
        pose: tuple[float, float, float] | None,
        started: float,
        state: dict[str, Any],
        goals: list[PoseStamped],
    ) -> None:
        feedback = action.Feedback()
        if pose is not None:
            feedback.current_pose.header.frame_id = self.global_frame
            feedback.current_pose.header.stamp = self.get_clock().now().to_msg()
            p = feedback.current_pose.pose
            p.position.x, p.position.y = pose[0], pose[1]
            p.orientation.z, p.orientation.w = math.sin(pose[2] / 2), math.cos(pose[2] / 2)
            feedback.distance_remaining = float(remaining_length(state["path"], pose))
        elapsed = time.monotonic() - started
        feedback.navigation_time = Duration(seconds=elapsed).to_msg()
        if self.speed > 0.01:
            remaining = feedback.distance_remaining / self.speed
            feedback.estimated_time_remaining = Duration(seconds=remaining).to_msg()
        feedback.number_of_recoveries = int(state["recoveries"])
        if action is NavigateThroughPoses:
            feedback.number_of_poses_remaining = len(goals)
        handle.publish_feedback(feedback)

    def plan_with_recovery(self, goals: list[PoseStamped], stop: Any) -> Path:
        """A plan, tried a second time as the tree's ComputePathToPose RecoveryNode does:
        after clearing the global costmap, for the codes a planner recovery may help with."""
        try:
            return self.plan(goals, stop)
        except NavigationFailed as exc:
            if exc.code not in PLANNER_RETRY or stop():
                raise
            self.get_logger().warning(
                f"Planning failed ({exc.code}: {exc}); clearing the global costmap and "
                "planning once more"
            )
            self.clear_costmaps(stop, (GLOBAL_COSTMAP,))
            self.recover("wait", stop)  # the costmap's next update takes in the scans again
            return self.plan(goals, stop)

    def plan(self, goals: list[PoseStamped], stop: Any) -> Path:
        """One path through ``goals`` (each leg a ComputePathToPose from the previous pose)."""
        poses: list[PoseStamped] = []
        start: PoseStamped | None = None
        for goal in goals:
            request = ComputePathToPose.Goal()
            request.goal = goal
            request.planner_id = str(self.get_parameter("planner_id").value)
            if start is not None:
                request.start, request.use_start = start, True
            outcome = self.call(self.planner, request, stop, "compute_path_to_pose")
            leg = outcome.result.path
            if outcome.status != SUCCEEDED or not leg.poses:
                raise NavigationFailed(
                    outcome.result.error_code, outcome.result.error_msg or "Planning failed"
                )
            poses.extend(leg.poses if not poses else leg.poses[1:])
            start = leg.poses[-1]
        path = Path()
        path.header.frame_id = self.global_frame
        path.header.stamp = self.get_clock().now().to_msg()
        path.poses = poses
        return path

    def call(self, client: ActionClient, request: Any, stop: Any, name: str) -> Any:
        if not client.wait_for_server(timeout_sec=5.0):
            raise NavigationFailed(0, f"Action server {name} is not available")
        sent = client.send_goal_async(request)
        if not wait_for(sent, 10.0, stop):
            raise NavigationFailed(0, f"{name} did not answer the goal")
        goal_handle: ClientGoalHandle = sent.result()
        if not goal_handle.accepted:
            raise NavigationFailed(0, f"{name} rejected the goal")
        done = goal_handle.get_result_async()
        if not wait_for(done, 30.0, stop):
            goal_handle.cancel_goal_async()
            raise NavigationFailed(0, f"{name} did not finish")
        return done.result()

    def follow(self, path: Path, stop: Any, owner: Any) -> Any:
        """Send the path to the controller; a future-like handle on its result."""
        request = FollowPath.Goal()
        request.path = path
        request.controller_id = str(self.get_parameter("controller_id").value)
        if not self.controller.wait_for_server(timeout_sec=5.0):
            raise NavigationFailed(0, "Action server follow_path is not available")
        sent = self.controller.send_goal_async(request, feedback_callback=self.on_follow_feedback)
        if not wait_for(sent, 10.0, stop):
            raise NavigationFailed(0, "follow_path did not answer the goal")
        goal_handle = sent.result()
        if not goal_handle.accepted:
            raise NavigationFailed(0, "follow_path rejected the goal")
        following = _Following(goal_handle, goal_handle.get_result_async())
        with self.lock:
            if self.current is owner:
                self.following = following
        if owner.is_cancel_requested:  # cancelled while the path was on its way
            goal_handle.cancel_goal_async()
        return following

    def cancel_follow(self, follow: Any) -> None:
        if follow is None:
            return
        cancel = follow.handle.cancel_goal_async()
        wait_for(cancel, 2.0)

    def destroy_node(self) -> None:
        stop_listener(self.tf_listener)
        super().destroy_node()


class _Following:
    def __init__(self, handle: ClientGoalHandle, result: Future) -> None:
        self.handle, self.future = handle, result

    @property
    def status(self) -> int | None:
        return int(self.handle.status)

    def done(self) -> bool:
        return self.future.done()

    def running(self) -> bool:
        """Still driving: no result yet, and no final status (the status can come first)."""
        return not self.done() and self.status not in FINAL_STATUSES

    def result(self) -> Any:
        return self.future.result()


def main(args: list[str] | None = None) -> int:
    return spin_server(BtNavigator, args, "bt_navigator")


if __name__ == "__main__":
    sys.exit(main())
