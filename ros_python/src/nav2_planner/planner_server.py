"""planner_server: Nav2's planner server, a lifecycle node with a global costmap and a planner.

``ros2 run nav2_planner planner_server`` starts it *unconfigured*; a
lifecycle manager (or ``ros2 lifecycle set /planner_server configure`` then
``activate``) brings it up. Then

- ``/global_costmap/global_costmap`` (in this process, as in Nav2) turns
  ``/map`` and the obstacles ``/scan`` sees into ``/global_costmap/costmap``
  (:mod:`nav2_costmap_2d.costmap_2d_ros`);
- the action ``compute_path_to_pose`` (nav2_msgs/action/ComputePathToPose)
  plans from the robot (TF ``map -> base_link``; or ``start`` with
  ``use_start``) to ``goal`` with the planner ``planner_id`` names (``""``:
  the only one, ``GridBased``), answers with the path and ``planning_time``
  and publishes it on ``/plan`` (nav_msgs/Path) right after; a failure ends
  the goal aborted with Jazzy's error code (``START_OUTSIDE_MAP``,
  ``GOAL_OUTSIDE_MAP``, ``GOAL_OCCUPIED``, ``NO_VALID_PATH``,
  ``INVALID_PLANNER``, ``TF_ERROR``...) and ``error_msg``.

Parameters: ``planner_plugins`` (``["GridBased"]``), ``expected_planner_frequency``
(1.0 Hz: a slower plan is warned about), and the planner's own
``GridBased.tolerance`` (0.5 m), ``GridBased.use_astar`` (false),
``GridBased.allow_unknown`` (true), as NavFn's. The planner is our NavFn-like
grid search (:mod:`nav2_planner.navfn_planner`); plugins are not loaded.
Not here: ``compute_path_through_poses``, ``is_path_valid``.
"""

from __future__ import annotations

import math
import sys
import threading
import time
from typing import Any

from geometry_msgs.msg import PoseStamped
from lifecycle_msgs.msg import State
from nav2_costmap_2d.costmap_2d_ros import Costmap2DROS, yaw_of
from nav2_msgs.action import ComputePathToPose
from nav2_util.lifecycle_node import LifecycleNode
from nav2_util.server_main import spin_server
from nav_msgs.msg import Path
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.duration import Duration
from rclpy.lifecycle import LifecycleState, TransitionCallbackReturn
from rclpy.lifecycle.publisher import LifecyclePublisher

from nav2_planner.navfn_planner import PlannerOptions, create_plan
from nav2_planner.planner_exceptions import (
    InvalidPlanner,
    PlannerCancelled,
    PlannerException,
    PlannerTFError,
)

Result = ComputePathToPose.Result


def yaw_to_quaternion(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def path_message(poses: list[tuple[float, float, float]], frame_id: str, stamp: Any) -> Path:
    path = Path()
    path.header.frame_id = frame_id
    path.header.stamp = stamp
    for x, y, yaw in poses:
        pose = PoseStamped()
        pose.header = path.header
        pose.pose.position.x, pose.pose.position.y = float(x), float(y)
        o = pose.pose.orientation
        o.x, o.y, o.z, o.w = yaw_to_quaternion(yaw)
        path.poses.append(pose)
    return path


class PlannerServer(LifecycleNode):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__("planner_server", **kwargs)
        self.get_logger().info("Creating")
        self.declare_parameter("planner_plugins", ["GridBased"])
        self.declare_parameter("expected_planner_frequency", 1.0)
        # How long a finished goal's result stays on the action server (and in its status
        # list): Nav2's planner server keeps it 10 s; rclpy's own default would be 900 s.
        self.declare_parameter("action_server_result_timeout", 10.0)
        self.declare_parameter("GridBased.plugin", "nav2_navfn_planner::NavfnPlanner")
        self.declare_parameter("GridBased.tolerance", 0.5)
        self.declare_parameter("GridBased.use_astar", False)
        self.declare_parameter("GridBased.allow_unknown", True)
        # As Nav2: the costmap is a node of its own, in this process, at the rates Nav2's
        # nav2_params.yaml gives the global costmap (update and publish once a second).
        self.costmap_ros = Costmap2DROS(
            "global_costmap",
            self.get_namespace(),
            defaults={"update_frequency": 1.0, "publish_frequency": 1.0},
        )
        self.planner_ids: list[str] = []
        self.max_planner_duration = 0.0
        self.plan_publisher: LifecyclePublisher | None = None
        self.action_server: ActionServer | None = None
        self.group = ReentrantCallbackGroup()
        self.goal_lock = threading.Lock()
        self.latest_goal: Any = None
        self.warned_default = False

    # --- transitions ---
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Configuring")
        self.costmap_ros.on_configure()
        self.planner_ids = [str(v) for v in self.get_parameter("planner_plugins").value or []]
        for planner_id in self.planner_ids:
            if not self.has_parameter(f"{planner_id}.plugin"):
                self.declare_parameter(f"{planner_id}.plugin", "nav2_navfn_planner::NavfnPlanner")
            for name, default in (("tolerance", 0.5), ("use_astar", False)):
                if not self.has_parameter(f"{planner_id}.{name}"):
                    self.declare_parameter(f"{planner_id}.{name}", default)
            if not self.has_parameter(f"{planner_id}.allow_unknown"):
                self.declare_parameter(f"{planner_id}.allow_unknown", True)
            plugin = self.get_parameter(f"{planner_id}.plugin").value
            self.get_logger().info(f"Created global planner plugin {planner_id} of type {plugin}")
        self.get_logger().info(
            f"Planner Server has {' '.join(self.planner_ids)} planners available."
        )
        frequency = float(self.get_parameter("expected_planner_frequency").value)
        if frequency > 0:
            self.max_planner_duration = 1.0 / frequency
        else:
            self.get_logger().warning(
                f"The expected planner frequency parameter is {frequency:.4f} Hz. The value "
                "should to be greater than 0.0 to turn on duration overrrun warning messages"
            )
            self.max_planner_duration = 0.0
        self.plan_publisher = self.create_lifecycle_publisher(Path, "plan", 1)
        self.action_server = ActionServer(
            self,
            ComputePathToPose,
            "compute_path_to_pose",
            execute_callback=self.compute_plan,
            goal_callback=self.on_goal,
            handle_accepted_callback=self.on_accepted,
            cancel_callback=lambda _goal: CancelResponse.ACCEPT,
            callback_group=self.group,
            result_timeout=float(self.get_parameter("action_server_result_timeout").value),
        )
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Activating")
        self.costmap_ros.on_activate()
        return super().on_activate(state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Deactivating")
        self.costmap_ros.on_deactivate()
        return super().on_deactivate(state)

    def release(self) -> None:
        if self.action_server is not None:
            self.action_server.destroy()
            self.action_server = None
        if self.plan_publisher is not None:
            self.destroy_lifecycle_publisher(self.plan_publisher)
            self.plan_publisher = None
        self.costmap_ros.on_cleanup()

    def active(self) -> bool:
        return self._state_machine.current_state[0] == State.PRIMARY_STATE_ACTIVE

    # --- the action ---
    def on_goal(self, goal: Any) -> GoalResponse:
        if not self.active():
            self.get_logger().warning("Action server is inactive. Rejecting the goal.")
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def on_accepted(self, handle: Any) -> None:
        with self.goal_lock:  # a newer goal preempts the one being planned
            self.latest_goal = handle
        handle.execute()

    def compute_plan(self, handle: Any) -> Any:
        started = time.monotonic()
        goal = handle.request
        result = Result()
        start: tuple[float, float, float] | None = None
        target = goal.goal.pose
        try:
            costmap = self.wait_for_costmap()
            if goal.use_start:
                p = goal.start.pose
                start = self.costmap_ros.transform_pose(
                    goal.start.header.frame_id, p.position.x, p.position.y, yaw_of(p.orientation)
                )
            else:
                start = self.costmap_ros.get_robot_pose()
            if start is None:
                raise PlannerTFError("Unable to transform poses to global frame")
            end = self.costmap_ros.transform_pose(
                goal.goal.header.frame_id,
                target.position.x,
                target.position.y,
                yaw_of(target.orientation),
            )
            if end is None:
                raise PlannerTFError("Unable to transform poses to global frame")
            planner_id = self.planner_for(goal.planner_id)

            def cancelled() -> bool:
                return handle.is_cancel_requested or handle is not self.latest_goal

            poses = create_plan(costmap, start, end, self.options(planner_id), cancelled)
            result.path = path_message(
                poses, self.costmap_ros.global_frame, self.get_clock().now().to_msg()
            )
            self.publish_plan_soon(result.path)
            duration = time.monotonic() - started
            result.planning_time = Duration(seconds=duration).to_msg()
            if self.max_planner_duration and duration > self.max_planner_duration:
                self.get_logger().warning(
                    "Planner loop missed its desired rate of "
                    f"{1 / self.max_planner_duration:.4f} Hz. Current loop rate is "
                    f"{1 / duration:.4f} Hz"
                )
            handle.succeed()
            return result
        except PlannerCancelled:
            self.get_logger().info("Goal was canceled. Canceling planning action.")
            if handle.is_cancel_requested:
                handle.canceled()
            else:
                handle.abort()
            return result
        except PlannerException as exc:
            s = start or (math.nan, math.nan, 0.0)
            self.get_logger().warning(
                f"{goal.planner_id} plugin failed to plan from ({s[0]:.2f}, {s[1]:.2f}) to "
                f'({target.position.x:0.2f}, {target.position.y:.2f}): "{exc}"'
            )
            result.error_code = exc.error_code
            result.error_msg = str(exc)
            handle.abort()
            return result

    def publish_plan_soon(self, path: Path) -> None:
        """/plan just after the result goes out, not before it (ours; Nav2 publishes first).

        /plan is for the eyes (rviz, the dashboard); the client waits for the result, and
        turning a path of a few hundred poses into bytes takes milliseconds of Python.
        """
        publisher = self.plan_publisher
        if publisher is None:
            return

        def publish() -> None:
            try:
                publisher.publish(path)
            except Exception:  # destroyed meanwhile (cleanup, shutdown): nobody to show it to
                pass

        timer = threading.Timer(0.01, publish)
        timer.daemon = True
        timer.start()

    def wait_for_costmap(self) -> Any:
        deadline = time.monotonic() + 5.0
        while True:
            costmap = self.costmap_ros.get_costmap()
            if costmap is not None:
                return costmap
            if time.monotonic() > deadline:
                raise PlannerException("No costmap yet: is a map published on /map?")
            time.sleep(0.05)

    def planner_for(self, planner_id: str) -> str:
        if planner_id in self.planner_ids:
            return planner_id
        if len(self.planner_ids) == 1 and not planner_id:
            if not self.warned_default:
                self.warned_default = True
                self.get_logger().warning(
                    "No planners specified in action call. Server will use only plugin "
                    f"{self.planner_ids[0]} in server. This warning will appear once."
                )
            return self.planner_ids[0]
        self.get_logger().error(
            f"planner {planner_id} is not a valid planner. "
            f"Planner names are: {' '.join(self.planner_ids)}"
        )
        raise InvalidPlanner(f"Planner id {planner_id} is invalid")

    def options(self, planner_id: str) -> PlannerOptions:
        g = self.get_parameter
        return PlannerOptions(
            tolerance=float(g(f"{planner_id}.tolerance").value),
            use_astar=bool(g(f"{planner_id}.use_astar").value),
            allow_unknown=bool(g(f"{planner_id}.allow_unknown").value),
        )

    def destroy_node(self) -> None:
        self.costmap_ros.destroy_node()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    return spin_server(PlannerServer, args, "planner_server")


if __name__ == "__main__":
    sys.exit(main())
