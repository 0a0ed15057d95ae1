"""waypoint_follower: Nav2's waypoint follower, a lifecycle node serving ``follow_waypoints``.

``ros2 run nav2_waypoint_follower waypoint_follower`` starts it *unconfigured*;
a lifecycle manager (or ``ros2 lifecycle set``) brings it up. Then the action
``follow_waypoints`` (nav2_msgs/action/FollowWaypoints) takes a list of poses
and sends them, one after the other, to the navigator's ``navigate_to_pose``,
as Nav2 Jazzy's follower does:

- it starts at the goal's ``goal_index`` and goes round the list
  ``number_of_loops`` more times after the first (0: once through);
- feedback ``current_waypoint`` is the index being driven to, sent at
  ``loop_rate`` (20 Hz);
- a waypoint the navigator fails (aborted, cancelled, or a goal it rejects)
  is put in the result's ``missed_waypoints`` with the navigator's error code
  (e.g. ComputePathToPose's ``GOAL_OCCUPIED`` 206 for a pose in a wall); with
  ``stop_on_failure`` (true) the action ends aborted there, without it the
  follower moves on to the next waypoint and the action ends succeeded with
  the misses listed;
- on arriving, the ``waypoint_task_executor_plugin`` (``wait_at_waypoint``,
  of type ``nav2_waypoint_follower::WaitAtWaypoint``: pause
  ``wait_at_waypoint.waypoint_pause_duration`` ms, 0 by default: off) runs;
  a task that fails is missed with ``TASK_EXECUTOR_FAILED`` (601);
- cancelling cancels the navigation being driven (the robot stops) and ends
  the action cancelled; a new goal preempts the running one (which ends aborted).

``loop_rate`` and ``stop_on_failure`` may be changed while it is active, as
upstream's dynamic parameters. Not here: ``follow_gps_waypoints`` (it needs
robot_localization's ``/fromLL``), and the other task executors
(``PhotoAtWaypoint``, ``InputAtWaypoint``): a plugin of another type fails
the configure transition with upstream's message.
"""

from __future__ import annotations

import sys
import threading
import time
from typing import Any

import rclpy
from lifecycle_msgs.msg import State
from nav2_msgs.action import FollowWaypoints, NavigateToPose
from nav2_msgs.msg import MissedWaypoint
from nav2_util.action_client import SerializedActionClient
from nav2_util.lifecycle_node import LifecycleNode
from nav2_util.server_main import spin_server
from rcl_interfaces.msg import SetParametersResult
from rclpy.action import ActionClient, ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.lifecycle import LifecycleState, TransitionCallbackReturn
from rclpy.parameter import Parameter

from nav2_waypoint_follower.plugins.wait_at_waypoint import PLUGIN_TYPE, WaitAtWaypoint

SUCCEEDED, CANCELED, ABORTED = 4, 5, 6  # action_msgs/GoalStatus
PROCESSING, NAV_SUCCEEDED, FAILED, UNKNOWN = "processing", "succeeded", "failed", "unknown"
TASK_EXECUTORS = {PLUGIN_TYPE: WaitAtWaypoint}


class NavigationGoal:
    """One ``navigate_to_pose`` goal in flight, and what became of it (``ActionStatus``)."""

    def __init__(self, node: WaypointFollower, client: ActionClient, pose: Any) -> None:
        self.node = node
        self.status = PROCESSING
        self.error_code = 0
        self.handle: Any = None
        self.lock = threading.Lock()
        goal = NavigateToPose.Goal()
        goal.pose = pose
        goal.pose.header.stamp = node.get_clock().now().to_msg()
        if not client.wait_for_server(timeout_sec=2.0):
            self.fail_to_send()
            return
        client.send_goal_async(goal).add_done_callback(self.on_goal_response)

    def fail_to_send(self) -> None:
        self.node.get_logger().error(
            "navigate_to_pose action client failed to send goal to server."
        )
        self.status = FAILED

    def on_goal_response(self, future: Any) -> None:
        handle = future.result()
        if handle is None or not handle.accepted:
            self.fail_to_send()
            return
        with self.lock:
            self.handle = handle
        handle.get_result_async().add_done_callback(self.on_result)

    def on_result(self, future: Any) -> None:
        response = future.result()
        status = response.status if response is not None else 0
        if status == SUCCEEDED:
            self.status = NAV_SUCCEEDED
        elif status == ABORTED:
            self.error_code = int(response.result.error_code)
            self.status = FAILED
        elif status == CANCELED:
            self.status = FAILED
        else:
            self.node.get_logger().error("Received an UNKNOWN result code from navigation action!")
            self.status = UNKNOWN

    def cancel(self, timeout: float = 2.0) -> None:
        """Cancel the navigation (the robot stops) and wait a little for the answer."""
        deadline = time.monotonic() + timeout
        done = threading.Event()
        while self.status == PROCESSING and time.monotonic() < deadline:
            with self.lock:
                handle = self.handle
            if handle is not None:
                handle.cancel_goal_async().add_done_callback(lambda _f: done.set())
                done.wait(max(deadline - time.monotonic(), 0.0))
                return
            time.sleep(0.02)  # the goal is still on its way to the navigator


class WaypointFollower(LifecycleNode):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__("waypoint_follower", **kwargs)
        self.get_logger().info("Creating")
        self.declare_parameter("stop_on_failure", True)
        self.declare_parameter("loop_rate", 20)
        self.declare_parameter("action_server_result_timeout", 900.0)
        self.declare_parameter("global_frame_id", "map")
        self.declare_parameter("waypoint_task_executor_plugin", "wait_at_waypoint")
        self.declare_parameter("wait_at_waypoint.plugin", PLUGIN_TYPE)
        self.group = ReentrantCallbackGroup()
        self.lock = threading.Lock()
        self.current: Any = None
        self.stop_on_failure = True
        self.loop_rate = 20
        self.nav_to_pose_client: ActionClient | None = None
        self.action_server: ActionServer | None = None
        self.task_executor: WaitAtWaypoint | None = None
        self.dyn_params_handler: Any = None

    # --- transitions ---
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Configuring")
        g = self.get_parameter
        self.stop_on_failure = bool(g("stop_on_failure").value)
        self.loop_rate = int(g("loop_rate").value)
        self.global_frame_id = str(g("global_frame_id").value).lstrip("/")
        executor_id = str(g("waypoint_task_executor_plugin").value)
        if not self.has_parameter(f"{executor_id}.plugin"):
            self.declare_parameter(f"{executor_id}.plugin", "")
        executor_type = str(g(f"{executor_id}.plugin").value)
        factory = TASK_EXECUTORS.get(executor_type)
        if factory is None:
            self.get_logger().fatal(
                "Failed to create waypoint_task_executor. Exception: According to the loaded "
                f"plugin descriptions the class {executor_type or '(none)'} with base class "
                "type nav2_core::WaypointTaskExecutor does not exist. Declared types are  "
                + " ".join(TASK_EXECUTORS)
            )
            return TransitionCallbackReturn.FAILURE
        self.task_executor = factory()
        self.get_logger().info(
            f"Created waypoint_task_executor : {executor_id} of type {executor_type}"
        )
        self.task_executor.initialize(self, executor_id)
        self.nav_to_pose_client = SerializedActionClient(
            self, NavigateToPose, "navigate_to_pose", callback_group=self.group
        )
        self.action_server = ActionServer(
            self,
            FollowWaypoints,
            "follow_waypoints",
            execute_callback=self.follow_waypoints,
            goal_callback=self.on_goal,
            handle_accepted_callback=self.on_accepted,
            cancel_callback=lambda _goal: CancelResponse.ACCEPT,
            callback_group=self.group,
            result_timeout=float(g("action_server_result_timeout").value),
        )
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Activating")
        self.add_on_set_parameters_callback(self.on_parameters)
        self.dyn_params_handler = self.on_parameters
        return super().on_activate(state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Deactivating")
        if self.dyn_params_handler is not None:
            self.remove_on_set_parameters_callback(self.dyn_params_handler)
            self.dyn_params_handler = None
        return super().on_deactivate(state)

    def release(self) -> None:
        with self.lock:
            self.current = None
        if self.action_server is not None:
            self.action_server.destroy()
            self.action_server = None
        if self.nav_to_pose_client is not None:
            self.nav_to_pose_client.destroy()
            self.nav_to_pose_client = None
        self.task_executor = None

    def active(self) -> bool:
        return self._state_machine.current_state[0] == State.PRIMARY_STATE_ACTIVE

    def on_parameters(self, parameters: list[Parameter]) -> SetParametersResult:
        for parameter in parameters:
            if parameter.name == "loop_rate" and parameter.type_ == Parameter.Type.INTEGER:
                self.loop_rate = int(parameter.value)
            elif parameter.name == "stop_on_failure" and parameter.type_ == Parameter.Type.BOOL:
                self.stop_on_failure = bool(parameter.value)
        return SetParametersResult(successful=True)

    # --- the action ---
    def on_goal(self, goal: Any) -> GoalResponse:
        if not self.active():
            self.get_logger().info("Action server is inactive. Rejecting the goal.")
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def on_accepted(self, handle: Any) -> None:
        with self.lock:  # a newer goal preempts the one being followed
            previous, self.current = self.current, handle
        if previous is not None:
            self.get_logger().info("Preempting the goal pose.")
        handle.execute()

    def follow_waypoints(self, handle: Any) -> Any:
        goal = handle.request
        result = FollowWaypoints.Result()
        feedback = FollowWaypoints.Feedback()
        poses = list(goal.poses)
        self.get_logger().info(f"Received follow waypoint request with {len(poses)} waypoints.")
        if not poses:
            result.error_msg = (
                "Empty vector of waypoints passed to waypoint following action potentially "
                "due to conversation failure or empty request."
            )
            self.get_logger().error(result.error_msg)
            handle.abort()
            return result
        index = int(goal.goal_index)
        if index >= len(poses):
            result.error_msg = (
                f"goal_index {index} is beyond the last of the {len(poses)} waypoints"
            )
            self.get_logger().error(result.error_msg)
            handle.abort()
            return result
        loops, loop_no = int(goal.number_of_loops), 0
        navigation: NavigationGoal | None = None
        while rclpy.ok():
            if handle.is_cancel_requested:
                if navigation is not None:
                    navigation.cancel()
                handle.canceled()
                return result
            if handle is not self.current or not self.active():
                if handle is self.current:  # deactivated under a running goal
                    self.get_logger().warning(
                        "Taking action server to deactive state with an active goal."
                    )
                    if navigation is not None:
                        navigation.cancel()
                handle.abort()  # preempted: the new goal's navigation replaces this one's
                return result
            if navigation is None:
                assert self.nav_to_pose_client is not None
                navigation = NavigationGoal(self, self.nav_to_pose_client, poses[index])
            feedback.current_waypoint = index
            handle.publish_feedback(feedback)

            status = navigation.status
            if status in (FAILED, UNKNOWN):
                result.missed_waypoints.append(
                    MissedWaypoint(index=index, goal=poses[index], error_code=navigation.error_code)
                )
                if self.stop_on_failure:
                    self.get_logger().warning(
                        f"Failed to process waypoint {index} in waypoint list and stop on "
                        "failure is enabled. Terminating action."
                    )
                    handle.abort()
                    return result
                self.get_logger().info(f"Failed to process waypoint {index}, moving to next.")
            elif status == NAV_SUCCEEDED:
                self.get_logger().info(
                    f"Succeeded processing waypoint {index}, processing waypoint task execution"
                )
                executor = self.task_executor
                executed = executor is not None and executor.process_at_waypoint(
                    poses[index], index
                )
                self.get_logger().info(
                    f"Task execution at waypoint {index} {'succeeded' if executed else 'failed!'}"
                )
                if not executed:
                    result.missed_waypoints.append(
                        MissedWaypoint(
                            index=index,
                            goal=poses[index],
                            error_code=FollowWaypoints.Result.TASK_EXECUTOR_FAILED,
                        )
                    )
                    if self.stop_on_failure:
                        self.get_logger().warning(
                            f"Failed to execute task at waypoint {index}  stop on failure is "
                            "enabled. Terminating action."
                        )
                        handle.abort()
                        return result
                self.get_logger().info(
                    f"Handled task execution on waypoint {index}, moving to next."
                )

            if status != PROCESSING:
                index += 1
                navigation = None
                if index >= len(poses):
                    if loop_no == loops:
                        self.get_logger().info(f"Completed all {len(poses)} waypoints requested.")
                        handle.succeed()
                        return result
                    self.get_logger().info(f"Starting a new loop, current loop count is {loop_no}")
                    index = 0
                    loop_no += 1
            time.sleep(1.0 / max(self.loop_rate, 1))
        handle.abort()
        return result


def main(args: list[str] | None = None) -> int:
    return spin_server(WaypointFollower, args, "waypoint_follower")


if __name__ == "__main__":
    sys.exit(main())
