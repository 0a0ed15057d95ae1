"""controller_server: Nav2's controller server, a lifecycle node that follows a path on /cmd_vel.

``ros2 run nav2_controller controller_server`` starts it *unconfigured*; a
lifecycle manager brings it up. Then the action ``follow_path``
(nav2_msgs/action/FollowPath) takes a nav_msgs/Path (in the costmap's frame,
``map``) and, ``controller_frequency`` (20 Hz) times a second,

- reads the robot's pose from TF (``map -> base_link``) through its
  ``/local_costmap/local_costmap`` node (in this process, as in Nav2), whose
  obstacle layer also holds what ``/scan`` sees that the map does not;
- checks progress (``progress_checker``: ``FAILED_TO_MAKE_PROGRESS``);
- computes a velocity with the regulated pure pursuit controller
  (``FollowPath``: :mod:`nav2_controller.regulated_pure_pursuit`) and
  publishes it on ``cmd_vel`` (geometry_msgs/Twist);
- sends feedback (``distance_to_goal`` along the path, ``speed`` from the
  odometry: ours reads it from TF's ``odom -> base_link``, where Nav2
  subscribes ``odom_topic``);
- ends when the goal checker (``goal_checker``: ``xy_goal_tolerance`` 0.15 m,
  ``yaw_goal_tolerance`` 0.25 rad) says the path's last pose is reached
  ("Reached the goal!"), and stops the robot (a zero Twist) then, on a
  cancel ("Cancellation was successful. Stopping the robot."; the zero Twist
  goes out the moment the cancel request comes, not at the next tick) and on
  any failure.

A new goal while one runs takes over ("Passing new path to controller.");
the old goal ends aborted, as Nav2's simple action server does. Error codes:
``INVALID_CONTROLLER``, ``INVALID_PATH``, ``TF_ERROR``, ``NO_VALID_CONTROL``
(collision ahead), ``FAILED_TO_MAKE_PROGRESS``, ``UNKNOWN``.

Parameters: ``controller_frequency``, ``controller_plugins`` (``["FollowPath"]``),
``goal_checker_plugins`` (``["goal_checker"]``), ``progress_checker_plugins``
(``["progress_checker"]``), ``FollowPath.<RPP parameter>``,
``goal_checker.xy_goal_tolerance``/``yaw_goal_tolerance``/``stateful``,
``progress_checker.required_movement_radius``/``movement_time_allowance``.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

from geometry_msgs.msg import Twist
from lifecycle_msgs.msg import State
from nav2_costmap_2d.costmap_2d_ros import Costmap2DROS, yaw_of
from nav2_msgs.action import FollowPath
from nav2_util.lifecycle_node import LifecycleNode
from nav2_util.server_main import spin_server
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.lifecycle import LifecycleState, TransitionCallbackReturn
from rclpy.lifecycle.publisher import LifecyclePublisher
from rclpy.time import Time

from nav2_controller.checkers import SimpleGoalChecker, SimpleProgressChecker
from nav2_controller.regulated_pure_pursuit import (
    ControllerException,
    NoValidControl,
    PathState,
    RPPParameters,
    closest_index,
    compute_velocity,
    path_length,
)

Result = FollowPath.Result
Pose2D = tuple[float, float, float]


class ControllerError(Exception):
    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


class ControllerServer(LifecycleNode):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__("controller_server", **kwargs)
        self.get_logger().info("Creating controller server")
        p = self.declare_parameter
        p("controller_frequency", 20.0)
        p("action_server_result_timeout", 10.0)  # Nav2's; rclpy's default is 900 s
        p("controller_plugins", ["FollowPath"])
        p("goal_checker_plugins", ["goal_checker"])
        p("progress_checker_plugins", ["progress_checker"])
        p("odom_topic", "odom")  # Nav2's; the speed comes from the odometry's TF here
        p(
            "FollowPath.plugin",
            "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController",
        )
        for field in dataclasses.fields(RPPParameters):
            p(f"FollowPath.{field.name}", field.default)
        p("goal_checker.plugin", "nav2_controller::SimpleGoalChecker")
        # Ours (Nav2: 0.25 m): the robot stops as soon as amcl puts it inside the tolerance, and
        # amcl's own error comes on top: with 0.25 m the office robot stopped up to 0.31 m away.
        p("goal_checker.xy_goal_tolerance", 0.15)
        p("goal_checker.yaw_goal_tolerance", 0.25)
        p("goal_checker.stateful", True)
        p("progress_checker.plugin", "nav2_controller::SimpleProgressChecker")
        p("progress_checker.required_movement_radius", 0.5)
        p("progress_checker.movement_time_allowance", 10.0)
        # The rates Nav2's nav2_params.yaml gives the local costmap: update 5 Hz, publish 2 Hz.
        self.costmap_ros = Costmap2DROS(
            "local_costmap",
            self.get_namespace(),
            defaults={"update_frequency": 5.0, "publish_frequency": 2.0},
        )
        self.group = ReentrantCallbackGroup()
        self.vel_publisher: LifecyclePublisher | None = None
        self.last_odom: tuple[int, float, float, float] | None = None  # stamp (ns), x, y, yaw
        self.action_server: ActionServer | None = None
        self.lock = threading.Lock()
        self.current: Any = None  # the goal handle being followed
        self.speed = (0.0, 0.0)
        self.goal_checker = SimpleGoalChecker()
        self.progress_checker = SimpleProgressChecker()

    # --- transitions ---
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Configuring controller interface")
        self.costmap_ros.on_configure()
        g = self.get_parameter
        self.get_logger().info("getting progress checker plugins..")
        self.get_logger().info("getting goal checker plugins..")
        self.frequency = float(g("controller_frequency").value)
        if float(g("FollowPath.max_robot_pose_search_dist").value) < 0.0:
            self.get_logger().warning(
                "Max robot search distance is negative, setting to max to search every point "
                "on path for the closest value."
            )
        self.get_logger().info(f"Controller frequency set to {self.frequency:.4f}Hz")
        self.controller_ids = [str(v) for v in g("controller_plugins").value or []]
        for cid in self.controller_ids:
            plugin = g("FollowPath.plugin").value if cid == "FollowPath" else "?"
            self.get_logger().info(f"Created controller : {cid} of type {plugin}")
        self.vel_publisher = self.create_lifecycle_publisher(Twist, "cmd_vel", 1)
        self.action_server = ActionServer(
            self,
            FollowPath,
            "follow_path",
            execute_callback=self.compute_control,
            goal_callback=self.on_goal,
            handle_accepted_callback=self.on_accepted,
            cancel_callback=self.on_cancel,
            callback_group=self.group,
            result_timeout=float(g("action_server_result_timeout").value),
        )
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Activating")
        self.costmap_ros.on_activate()
        return super().on_activate(state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Deactivating")
        with self.lock:
            self.current = None  # a running goal sees it and stops the robot
        self.publish_zero_velocity()
        self.costmap_ros.on_deactivate()
        return super().on_deactivate(state)

    def release(self) -> None:
        with self.lock:
            self.current = None
        if self.action_server is not None:
            self.action_server.destroy()
            self.action_server = None
        if self.vel_publisher is not None:
            self.destroy_lifecycle_publisher(self.vel_publisher)
            self.vel_publisher = None
        self.costmap_ros.on_cleanup()

    def active(self) -> bool:
        return self._state_machine.current_state[0] == State.PRIMARY_STATE_ACTIVE

    # --- inputs and outputs ---
    def update_speed(self) -> None:
        """The robot's speed from two odometry poses on TF (odom -> base_link).

        Ours: an /odom subscription would wake this server's multi-threaded executor 60 times a
        wall second (the world at twice real time), a few milliseconds of Python each; TF
        already comes on a thread of its own. The same odometry, differentiated over the
        control period, as Nav2's odometry smoother averages it.
        """
        odom = self.costmap_ros.odom_frame()
        if odom is None:
            return
        try:
            tf = self.costmap_ros.tf_buffer.lookup_transform(
                odom, self.costmap_ros.robot_base_frame, Time()
            )
        except Exception:  # not on TF (yet): the speed stays as it was
            return
        stamp = Time.from_msg(tf.header.stamp).nanoseconds
        t, yaw = tf.transform.translation, yaw_of(tf.transform.rotation)
        last, self.last_odom = self.last_odom, (stamp, t.x, t.y, yaw)
        if last is None or stamp <= last[0]:
            if last is not None and stamp == last[0]:
                self.last_odom = last  # no newer odometry: measure over a longer span next
            return
        dt = (stamp - last[0]) * 1e-9
        if dt > 1.0:  # odometry that stood still for a second (or a reset): start again
            self.speed = (0.0, 0.0)
            return
        dx, dy = t.x - last[1], t.y - last[2]
        along = dx * math.cos(last[3]) + dy * math.sin(last[3])
        turn = math.atan2(math.sin(yaw - last[3]), math.cos(yaw - last[3]))
        self.speed = (along / dt, turn / dt)

    def publish_velocity(self, linear: float, angular: float) -> None:
        if self.vel_publisher is not None and self.active():
            twist = Twist()
            twist.linear.x, twist.angular.z = float(linear), float(angular)
            self.vel_publisher.publish(twist)

    def publish_zero_velocity(self) -> None:
        self.publish_velocity(0.0, 0.0)

    # --- the action ---
    def on_goal(self, goal: Any) -> GoalResponse:
        if not self.active():
            self.get_logger().warning("Action server is inactive. Rejecting the goal.")
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def on_cancel(self, handle: Any) -> CancelResponse:
        # Stop at once; the control loop sees the request on its next tick and ends the goal.
        with self.lock:
            mine = handle is self.current
        if mine:
            self.publish_zero_velocity()
        return CancelResponse.ACCEPT

    def on_accepted(self, handle: Any) -> None:
        with self.lock:
            previous, self.current = self.current, handle
        if previous is not None:
            self.get_logger().info("Passing new path to controller.")
            handle.preempted = True  # keep the progress checker's memory
        handle.execute()

    def compute_control(self, handle: Any) -> Any:
        if not getattr(handle, "preempted", False):
            self.get_logger().info("Received a goal, begin computing control effort.")
            self.progress_checker.reset()
        self.goal_checker.reset()
        result = Result()
        period = 1.0 / max(self.frequency, 0.1)
        try:
            path, frame = self.check_goal(handle.request)
            checker = self.make_goal_checker()
            params = self.rpp_parameters()
            search_dist = params.max_robot_pose_search_dist
            if search_dist < 0.0:  # Nav2 warns at configure and then searches the whole path
                search_dist = math.inf
            radius = float(self.costmap_ros.get_parameter("robot_radius").value)
            start = 0
            state = PathState()  # this path's own (Nav2's setPlan starts it afresh)
            while True:
                tick = time.monotonic()
                with self.lock:
                    mine = handle is self.current
                if not mine:  # a newer path took over, or the server was deactivated
                    handle.abort()
                    return result
                if handle.is_cancel_requested:
                    self.end_goal(
                        handle, handle.canceled, "Cancellation was successful. Stopping the robot."
                    )
                    return result
                pose = self.costmap_ros.get_robot_pose()
                if pose is None:
                    raise ControllerError(Result.TF_ERROR, "Failed to obtain robot pose")
                self.update_speed()
                # Nav2's order: the goal first, then progress (by the node's clock: simulated
                # time under use_sim_time), then the command.
                if checker.is_goal_reached(pose, path[-1]):
                    self.end_goal(handle, handle.succeed, "Reached the goal!")
                    return result
                now = self.get_clock().now().nanoseconds * 1e-9
                if not self.progress_checker.check(pose, now):
                    raise ControllerError(Result.FAILED_TO_MAKE_PROGRESS, "Failed to make progress")
                start = closest_index(path, pose, start, search_dist)
                try:
                    command = compute_velocity(
                        pose,
                        path[start:],
                        self.speed,
                        params,
                        goal_dist_tol=checker.xy_goal_tolerance,
                        costmap=self.costmap_ros.get_costmap(),
                        dt=period,
                        inscribed_radius=radius,
                        state=state,
                    )
                except NoValidControl as exc:
                    raise ControllerError(Result.NO_VALID_CONTROL, str(exc)) from exc
                except ControllerException as exc:
                    raise ControllerError(Result.UNKNOWN, str(exc)) from exc
                if handle.is_cancel_requested:
                    continue  # the next tick ends it: no step after a cancel's zero Twist
                self.publish_velocity(command.linear, command.angular)
                feedback = FollowPath.Feedback()
                feedback.distance_to_goal = float(
                    math.hypot(path[start][0] - pose[0], path[start][1] - pose[1])
                    + path_length(path, start)
                )
                feedback.speed = float(math.hypot(self.speed[0], 0.0))
                handle.publish_feedback(feedback)
                spent = time.monotonic() - tick
                if spent > period:
                    self.get_logger().warning(
                        f"Control loop missed its desired rate of {self.frequency:.4f} Hz. "
                        f"Current loop rate is {1 / spent:.4f} Hz.",
                        throttle_duration_sec=5.0,
                    )
                else:
                    time.sleep(period - spent)
        except ControllerError as exc:
            self.get_logger().error(str(exc))
            with self.lock:
                mine = self.current is handle
                if mine:
                    self.current = None
            if mine:
                self.publish_zero_velocity()
            result.error_code = exc.code
            result.error_msg = str(exc)
            handle.abort()
            return result

    def end_goal(self, handle: Any, end: Callable[[], object], message: str) -> None:
        """Say so, stop the robot, end the goal (succeed or canceled), free the server."""
        self.get_logger().info(message)
        self.publish_zero_velocity()
        end()
        with self.lock:
            if self.current is handle:
                self.current = None

    def check_goal(self, goal: Any) -> tuple[list[Pose2D], str]:
        if goal.controller_id not in ("", *self.controller_ids):
            raise ControllerError(
                Result.INVALID_CONTROLLER, f"Failed to find controller name: {goal.controller_id}"
            )
        if goal.goal_checker_id not in ("", "goal_checker"):
            raise ControllerError(
                Result.UNKNOWN, f"Failed to find goal checker name: {goal.goal_checker_id}"
            )
        if goal.progress_checker_id not in ("", "progress_checker"):
            raise ControllerError(
                Result.UNKNOWN, f"Failed to find progress checker name: {goal.progress_checker_id}"
            )
        if not goal.path.poses:
            raise ControllerError(Result.INVALID_PATH, "Path is empty.")
        frame = goal.path.header.frame_id or self.costmap_ros.global_frame
        path: list[Pose2D] = []
        for stamped in goal.path.poses:
            p = stamped.pose
            pose = self.costmap_ros.transform_pose(
                stamped.header.frame_id or frame,
                p.position.x,
                p.position.y,
                yaw_of(p.orientation),
            )
            if pose is None:
                raise ControllerError(Result.TF_ERROR, "Unable to transform the path")
            path.append(pose)
        return path, frame

    def make_goal_checker(self) -> SimpleGoalChecker:
        g = self.get_parameter
        self.goal_checker.xy_goal_tolerance = float(g("goal_checker.xy_goal_tolerance").value)
        self.goal_checker.yaw_goal_tolerance = float(g("goal_checker.yaw_goal_tolerance").value)
        self.goal_checker.stateful = bool(g("goal_checker.stateful").value)
        self.progress_checker.required_movement_radius = float(
            g("progress_checker.required_movement_radius").value
        )
        self.progress_checker.movement_time_allowance = float(
            g("progress_checker.movement_time_allowance").value
        )
        return self.goal_checker

    def rpp_parameters(self) -> RPPParameters:
        values = {
            field.name: type(field.default)(  # type: ignore[misc]
                self.get_parameter(f"FollowPath.{field.name}").value
            )
            for field in dataclasses.fields(RPPParameters)
        }
        return RPPParameters(**values)

    def destroy_node(self) -> None:
        self.costmap_ros.destroy_node()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    return spin_server(ControllerServer, args, "controller_server")


if __name__ == "__main__":
    sys.exit(main())
