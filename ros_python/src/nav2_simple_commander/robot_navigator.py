"""BasicNavigator: Nav2 Jazzy's Python API for sending a robot places, as a learner imports it.

A ``BasicNavigator`` is a node. Each task method (``goToPose``,
``goThroughPoses``, ``followWaypoints``, ``followPath``, ``spin``,
``backup``, ``driveOnHeading``) waits for its action server, sends one goal
and returns at once: True when the server accepted it, False when it was
rejected. The script then polls ``isTaskComplete()`` (which spins the node
for up to 0.1 s, so feedback arrives), reads ``getFeedback()`` on the way,
and asks ``getResult()`` for a ``TaskResult`` at the end; ``cancelTask()``
cancels the task in flight. ``getPath`` asks the planner for a
``nav_msgs/Path`` and blocks until it has one (None when planning failed).

The servers are Nav2's, by Nav2's names (relative, so a namespace given to
the navigator applies to them as well): the actions ``navigate_to_pose``,
``navigate_through_poses``, ``follow_waypoints``, ``follow_path``,
``compute_path_to_pose``, ``spin``, ``backup``, ``drive_on_heading``; the
services ``map_server/load_map``, ``global_costmap/...`` and
``local_costmap/...`` (clear and get the costmaps), ``<node>/get_state``
(lifecycle) and every ``nav2_msgs/srv/ManageLifecycleNodes`` service in the
graph; the topics ``initialpose`` (published) and ``amcl_pose`` (heard,
transient local, as amcl latches it).

Methods whose interfaces ROS 2 Classroom's ``nav2_msgs`` does not have yet
(``getPathThroughPoses``, ``smoothPath``, ``assistedTeleop``,
``followGpsWaypoints``, docking, the partial costmap clears) log an error
saying so and return what Nav2 returns on failure (False, or None). They
work as Nav2's do as soon as the interface is generated.

Like Nav2's, a method that waits for a server waits as long as it takes,
saying so once a second: the server may still be starting.
"""

from __future__ import annotations

import math
import time
import weakref
from enum import Enum
from typing import Any

import nav2_msgs.action
import nav2_msgs.srv
import rclpy
from action_msgs.msg import GoalStatus
from builtin_interfaces.msg import Duration
from geometry_msgs.msg import Point, PoseStamped, PoseWithCovarianceStamped
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
from rclpy.action import ActionClient
from rclpy.action.client import ClientGoalHandle
from rclpy.node import Node
from rclpy.qos import QoSDurabilityPolicy, QoSHistoryPolicy, QoSProfile, QoSReliabilityPolicy
from rclpy.task import Future

# Interfaces of Nav2 Jazzy that our nav2_msgs may not generate (yet): None when absent.
ComputePathThroughPoses: Any = getattr(nav2_msgs.action, "ComputePathThroughPoses", None)
SmoothPath: Any = getattr(nav2_msgs.action, "SmoothPath", None)
AssistedTeleop: Any = getattr(nav2_msgs.action, "AssistedTeleop", None)
FollowGPSWaypoints: Any = getattr(nav2_msgs.action, "FollowGPSWaypoints", None)
DockRobot: Any = getattr(nav2_msgs.action, "DockRobot", None)
UndockRobot: Any = getattr(nav2_msgs.action, "UndockRobot", None)
ClearCostmapExceptRegion: Any = getattr(nav2_msgs.srv, "ClearCostmapExceptRegion", None)
ClearCostmapAroundRobot: Any = getattr(nav2_msgs.srv, "ClearCostmapAroundRobot", None)
ClearCostmapAroundPose: Any = getattr(nav2_msgs.srv, "ClearCostmapAroundPose", None)

MANAGE_NODES_TYPE = "nav2_msgs/srv/ManageLifecycleNodes"


_WAKING: weakref.WeakSet[Future] = weakref.WeakSet()  # futures that already wake the executor


def _spin_until_done(node: Node, future: Future, timeout_sec: float | None = None) -> None:
    """``rclpy.spin_until_future_complete(node, future, timeout_sec=...)``, without its pile-up.

    rclpy 7.1 (Jazzy's, the wheel on PyPI) adds a done callback to the future on every
    turn of its loop and again on every call; each becomes a task when the future ends,
    and leftover tasks make the next wait turn without waiting (ros2/rclpy#1374, #1702).
    A navigator polls ``isTaskComplete`` and plans again and again, so that grew into a
    loop taking a core while it waited (measured: about 760 turns and 0.35 s of CPU for a
    90 ms plan). Here: one wake callback per future, and plain ``spin_once`` turns on the
    same global executor, added and removed as rclpy does.
    """
    executor = rclpy.get_global_executor()
    if future not in _WAKING:
        _WAKING.add(future)
        future.add_done_callback(lambda _f: executor.wake())
    deadline = None if timeout_sec is None or timeout_sec < 0 else time.monotonic() + timeout_sec
    added = executor.add_node(node)
    try:
        while executor.context.ok() and not future.done():
            if deadline is None:
                executor.spin_once()
                continue
            left = deadline - time.monotonic()
            if left <= 0:
                return
            executor.spin_once(timeout_sec=left)
    finally:
        if added:
            executor.remove_node(node)


class TaskResult(Enum):
    UNKNOWN = 0
    SUCCEEDED = 1
    CANCELED = 2
    FAILED = 3


def _duration(seconds: float) -> Duration:
    """A builtin_interfaces/Duration; Nav2 takes whole seconds, a float is welcome here too."""
    if isinstance(seconds, int):
        return Duration(sec=seconds)
    whole = math.floor(seconds)
    return Duration(sec=int(whole), nanosec=int(round((seconds - whole) * 1e9)) % 1_000_000_000)


class BasicNavigator(Node):
    """Nav2's Simple Commander: a node that sends navigation tasks and follows them."""

    def __init__(self, node_name: str = "basic_navigator", namespace: str = "") -> None:
        super().__init__(node_name=node_name, namespace=namespace)
        self.initial_pose = PoseStamped()
        self.initial_pose.header.frame_id = "map"
        self.goal_handle: ClientGoalHandle | None = None
        self.result_future: Future | None = None
        self.feedback: Any = None
        self.status: int | None = None

        # amcl latches its pose: a navigator started later still hears the newest one.
        amcl_pose_qos = QoSProfile(
            durability=QoSDurabilityPolicy.TRANSIENT_LOCAL,
            reliability=QoSReliabilityPolicy.RELIABLE,
            history=QoSHistoryPolicy.KEEP_LAST,
            depth=1,
        )
        self.initial_pose_received = False

        self.nav_through_poses_client = ActionClient(
            self, NavigateThroughPoses, "navigate_through_poses"
        )
        self.nav_to_pose_client = ActionClient(self, NavigateToPose, "navigate_to_pose")
        self.follow_waypoints_client = ActionClient(self, FollowWaypoints, "follow_waypoints")
        self.follow_gps_waypoints_client = self._optional_action(
            FollowGPSWaypoints, "follow_gps_waypoints"
        )
        self.follow_path_client = ActionClient(self, FollowPath, "follow_path")
        self.compute_path_to_pose_client = ActionClient(
            self, ComputePathToPose, "compute_path_to_pose"
        )
        self.compute_path_through_poses_client = self._optional_action(
            ComputePathThroughPoses, "compute_path_through_poses"
        )
        self.smoother_client = self._optional_action(SmoothPath, "smooth_path")
        self.spin_client = ActionClient(self, Spin, "spin")
        self.backup_client = ActionClient(self, BackUp, "backup")
        self.drive_on_heading_client = ActionClient(self, DriveOnHeading, "drive_on_heading")
        self.assisted_teleop_client = self._optional_action(AssistedTeleop, "assisted_teleop")
        self.docking_client = self._optional_action(DockRobot, "dock_robot")
        self.undocking_client = self._optional_action(UndockRobot, "undock_robot")

        self.localization_pose_sub = self.create_subscription(
            PoseWithCovarianceStamped, "amcl_pose", self._amclPoseCallback, amcl_pose_qos
        )
        self.initial_pose_pub = self.create_publisher(PoseWithCovarianceStamped, "initialpose", 10)

        self.change_maps_srv = self.create_client(LoadMap, "map_server/load_map")
        self.clear_costmap_global_srv = self.create_client(
            ClearEntireCostmap, "global_costmap/clear_entirely_global_costmap"
        )
        self.clear_costmap_local_srv = self.create_client(
            ClearEntireCostmap, "local_costmap/clear_entirely_local_costmap"
        )
        self.clear_costmap_except_region_srv = self._optional_service(
            ClearCostmapExceptRegion, "local_costmap/clear_costmap_except_region"
        )
        self.clear_costmap_around_robot_srv = self._optional_service(
            ClearCostmapAroundRobot, "local_costmap/clear_costmap_around_robot"
        )
        self.clear_costmap_around_pose_srv = self._optional_service(
            ClearCostmapAroundPose, "local_costmap/clear_costmap_around_pose"
        )
        self.get_costmap_global_srv = self.create_client(GetCostmap, "global_costmap/get_costmap")
        self.get_costmap_local_srv = self.create_client(GetCostmap, "local_costmap/get_costmap")

    def _optional_action(self, action_type: Any, name: str) -> ActionClient | None:
        return None if action_type is None else ActionClient(self, action_type, name)

    def _optional_service(self, srv_type: Any, name: str) -> Any:
        return None if srv_type is None else self.create_client(srv_type, name)

    def _unavailable(self, interface: str) -> None:
        self.error(
            f"'{interface}' is not available: ROS 2 Classroom's nav2_msgs does not have "
            "this interface yet, so no server offers it"
        )

    def destroyNode(self) -> None:
        self.destroy_node()

    def destroy_node(self) -> None:
        for client in (
            self.nav_through_poses_client,
            self.nav_to_pose_client,
            self.follow_waypoints_client,
            self.follow_path_client,
            self.compute_path_to_pose_client,
            self.compute_path_through_poses_client,
            self.smoother_client,
            self.spin_client,
            self.backup_client,
            self.drive_on_heading_client,
            self.assisted_teleop_client,
            self.follow_gps_waypoints_client,
            self.docking_client,
            self.undocking_client,
        ):
            if client is not None:
                client.destroy()
        super().destroy_node()

    # -- localization ---------------------------------------------------------------------

    def setInitialPose(self, initial_pose: PoseStamped) -> None:
        """Set the initial pose to the localization system."""
        self.initial_pose_received = False
        self.initial_pose = initial_pose
        # A navigator made a moment ago may not know amcl yet: give discovery a moment,
        # or the pose is published to nobody (waitUntilNav2Active publishes it again).
        deadline = time.monotonic() + 1.0
        while self.initial_pose_pub.get_subscription_count() == 0 and time.monotonic() < deadline:
            time.sleep(0.02)
        self._setInitialPose()

    # -- tasks ----------------------------------------------------------------------------

    def _sendTask(
        self,
        client: ActionClient,
        goal_msg: Any,
        server: str,
        announce: str,
        rejected: str,
        *,
        feedback: bool = True,
    ) -> bool:
        """Wait for the server, send the goal, and keep its handle: True when accepted."""
        self.debug(f"Waiting for '{server}' action server")
        while not client.wait_for_server(timeout_sec=1.0):
            self.info(f"'{server}' action server not available, waiting...")
        self.info(announce)
        send_goal_future = client.send_goal_async(
            goal_msg, self._feedbackCallback if feedback else None
        )
        _spin_until_done(self, send_goal_future)
        self.goal_handle = send_goal_future.result()
        if self.goal_handle is None or not self.goal_handle.accepted:
            self.error(rejected)
            return False
        self.result_future = self.goal_handle.get_result_async()
        return True

    def goThroughPoses(self, poses: list[PoseStamped], behavior_tree: str = "") -> bool:
        """Send a `NavThroughPoses` action request."""
        goal_msg = NavigateThroughPoses.Goal(poses=poses, behavior_tree=behavior_tree)
        return self._sendTask(
            self.nav_through_poses_client,
            goal_msg,
            "NavigateThroughPoses",
            f"Navigating with {len(goal_msg.poses)} goals....",
            f"Goal with {len(poses)} poses was rejected!",
        )

    def goToPose(self, pose: PoseStamped, behavior_tree: str = "") -> bool:
        """Send a `NavToPose` action request."""
        x, y = pose.pose.position.x, pose.pose.position.y
        return self._sendTask(
            self.nav_to_pose_client,
            NavigateToPose.Goal(pose=pose, behavior_tree=behavior_tree),
            "NavigateToPose",
            f"Navigating to goal: {x} {y}...",
            f"Goal to {x} {y} was rejected!",
        )

    def followWaypoints(self, poses: list[PoseStamped]) -> bool:
        """Send a `FollowWaypoints` action request."""
        goal_msg = FollowWaypoints.Goal(poses=poses)
        return self._sendTask(
            self.follow_waypoints_client,
            goal_msg,
            "FollowWaypoints",
            f"Following {len(goal_msg.poses)} goals....",
            f"Following {len(poses)} waypoints request was rejected!",
        )

    def followGpsWaypoints(self, gps_poses: list[Any]) -> bool:
        """Send a `FollowGPSWaypoints` action request."""
        if self.follow_gps_waypoints_client is None:
            self._unavailable("FollowGPSWaypoints")
            return False
        goal_msg = FollowGPSWaypoints.Goal(gps_poses=gps_poses)
        return self._sendTask(
            self.follow_gps_waypoints_client,
            goal_msg,
            "FollowWaypoints",
            f"Following {len(goal_msg.gps_poses)} gps goals....",
            f"Following {len(gps_poses)} gps waypoints request was rejected!",
        )

    def spin(self, spin_dist: float = 1.57, time_allowance: float = 10) -> bool:
        goal_msg = Spin.Goal(target_yaw=float(spin_dist), time_allowance=_duration(time_allowance))
        return self._sendTask(
            self.spin_client,
            goal_msg,
            "Spin",
            f"Spinning to angle {goal_msg.target_yaw}....",
            "Spin request was rejected!",
        )

    def backup(
        self, backup_dist: float = 0.15, backup_speed: float = 0.025, time_allowance: float = 10
    ) -> bool:
        goal_msg = BackUp.Goal(
            target=Point(x=float(backup_dist)),
            speed=float(backup_speed),
            time_allowance=_duration(time_allowance),
        )
        return self._sendTask(
            self.backup_client,
            goal_msg,
            "Backup",
            f"Backing up {goal_msg.target.x} m at {goal_msg.speed} m/s....",
            "Backup request was rejected!",
        )

    def driveOnHeading(
        self, dist: float = 0.15, speed: float = 0.025, time_allowance: float = 10
    ) -> bool:
        goal_msg = DriveOnHeading.Goal(
            target=Point(x=float(dist)),
            speed=float(speed),
            time_allowance=_duration(time_allowance),
        )
        return self._sendTask(
            self.drive_on_heading_client,
            goal_msg,
            "DriveOnHeading",
            f"Drive {goal_msg.target.x} m on heading at {goal_msg.speed} m/s....",
            "Drive On Heading request was rejected!",
        )

    def assistedTeleop(self, time_allowance: float = 30) -> bool:
        if self.assisted_teleop_client is None:
            self._unavailable("AssistedTeleop")
            return False
        goal_msg = AssistedTeleop.Goal(time_allowance=_duration(time_allowance))
        return self._sendTask(
            self.assisted_teleop_client,
            goal_msg,
            "assisted_teleop",
            "Running 'assisted_teleop'....",
            "Assisted Teleop request was rejected!",
        )

    def followPath(self, path: Any, controller_id: str = "", goal_checker_id: str = "") -> bool:
        """Send a `FollowPath` action request."""
        goal_msg = FollowPath.Goal(
            path=path, controller_id=controller_id, goal_checker_id=goal_checker_id
        )
        return self._sendTask(
            self.follow_path_client,
            goal_msg,
            "FollowPath",
            "Executing path...",
            "Follow path was rejected!",
        )

    def dockRobotByPose(
        self, dock_pose: PoseStamped, dock_type: str, nav_to_dock: bool = True
    ) -> bool:
        """Send a `DockRobot` action request."""
        if self.docking_client is None:
            self._unavailable("DockRobot")
            return False
        goal_msg = DockRobot.Goal(
            use_dock_id=False,
            dock_pose=dock_pose,
            dock_type=dock_type,
            navigate_to_staging_pose=nav_to_dock,
        )
        return self._sendTask(
            self.docking_client,
            goal_msg,
            "DockRobot",
            f"Docking at pose: {dock_pose}...",
            "Docking request was rejected!",
        )

    def dockRobotByID(self, dock_id: str, nav_to_dock: bool = True) -> bool:
        """Send a `DockRobot` action request."""
        if self.docking_client is None:
            self._unavailable("DockRobot")
            return False
        goal_msg = DockRobot.Goal(
            use_dock_id=True, dock_id=dock_id, navigate_to_staging_pose=nav_to_dock
        )
        return self._sendTask(
            self.docking_client,
            goal_msg,
            "DockRobot",
            f"Docking at dock ID: {dock_id}...",
            "Docking request was rejected!",
        )

    def undockRobot(self, dock_type: str = "") -> bool:
        """Send a `UndockRobot` action request."""
        if self.undocking_client is None:
            self._unavailable("UndockRobot")
            return False
        return self._sendTask(
            self.undocking_client,
            UndockRobot.Goal(dock_type=dock_type),
            "UndockRobot",
            f"Undocking from dock of type: {dock_type}...",
            "Undocking request was rejected!",
        )

    def cancelTask(self) -> None:
        """Cancel pending task request of any type."""
        self.info("Canceling current task.")
        if self.result_future and self.goal_handle is not None:
            future = self.goal_handle.cancel_goal_async()
            _spin_until_done(self, future)

    def isTaskComplete(self) -> bool:
        """Check if the task request of any type is complete yet."""
        if not self.result_future:
            # no task sent yet: nothing is pending
            return True
        _spin_until_done(self, self.result_future, timeout_sec=0.10)
        response = self.result_future.result()
        if not response:
            # still running
            return False
        self.status = response.status
        if self.status != GoalStatus.STATUS_SUCCEEDED:
            self.debug(f"Task with failed with status code: {self.status}")
            return True
        self.debug("Task succeeded!")
        return True

    def getFeedback(self) -> Any:
        """Get the pending action feedback message."""
        return self.feedback

    def getResult(self) -> TaskResult:
        """Get the pending action result message."""
        if self.status == GoalStatus.STATUS_SUCCEEDED:
            return TaskResult.SUCCEEDED
        if self.status == GoalStatus.STATUS_ABORTED:
            return TaskResult.FAILED
        if self.status == GoalStatus.STATUS_CANCELED:
            return TaskResult.CANCELED
        return TaskResult.UNKNOWN

    def waitUntilNav2Active(self, navigator: str = "bt_navigator", localizer: str = "amcl") -> None:
        """Block until the full navigation system is up and running."""
        if localizer != "robot_localization":  # robot_localization is no lifecycle node
            self._waitForNodeToActivate(localizer)
        if localizer == "amcl":
            self._waitForInitialPose()
        self._waitForNodeToActivate(navigator)
        self.info("Nav2 is ready for use!")

    # -- planning -------------------------------------------------------------------------

    def _planResult(
        self, client: ActionClient, goal_msg: Any, server: str, doing: str, rejected: str
    ) -> Any:
        """Send a planning goal and block until its result: the whole result message, or None."""
        self.debug(f"Waiting for '{server}' action server")
        while not client.wait_for_server(timeout_sec=1.0):
            self.info(f"'{server}' action server not available, waiting...")
        self.info(doing)
        send_goal_future = client.send_goal_async(goal_msg)
        _spin_until_done(self, send_goal_future)
        self.goal_handle = send_goal_future.result()
        if self.goal_handle is None or not self.goal_handle.accepted:
            self.error(rejected)
            return None
        self.result_future = self.goal_handle.get_result_async()
        _spin_until_done(self, self.result_future)
        response = self.result_future.result()
        self.status = response.status
        return response.result

    def _pathFrom(self, result: Any) -> Any:
        if self.status != GoalStatus.STATUS_SUCCEEDED:
            self.warn(f"Getting path failed with status code: {self.status}")
            return None
        return None if not result else result.path

    def _getPathImpl(
        self, start: PoseStamped, goal: PoseStamped, planner_id: str = "", use_start: bool = False
    ) -> Any:
        """Send a `ComputePathToPose` action request; the whole result, not just the path."""
        goal_msg = ComputePathToPose.Goal(
            start=start, goal=goal, planner_id=planner_id, use_start=use_start
        )
        return self._planResult(
            self.compute_path_to_pose_client,
            goal_msg,
            "ComputePathToPose",
            "Getting path...",
            "Get path was rejected!",
        )

    def getPath(
        self, start: PoseStamped, goal: PoseStamped, planner_id: str = "", use_start: bool = False
    ) -> Any:
        """Send a `ComputePathToPose` action request."""
        return self._pathFrom(self._getPathImpl(start, goal, planner_id, use_start))

    def _getPathThroughPosesImpl(
        self,
        start: PoseStamped,
        goals: list[PoseStamped],
        planner_id: str = "",
        use_start: bool = False,
    ) -> Any:
        """Send a `ComputePathThroughPoses` action request; the whole result."""
        if self.compute_path_through_poses_client is None:
            self._unavailable("ComputePathThroughPoses")
            return None
        goal_msg = ComputePathThroughPoses.Goal(
            start=start, goals=goals, planner_id=planner_id, use_start=use_start
        )
        return self._planResult(
            self.compute_path_through_poses_client,
            goal_msg,
            "ComputePathThroughPoses",
            "Getting path...",
            "Get path was rejected!",
        )

    def getPathThroughPoses(
        self,
        start: PoseStamped,
        goals: list[PoseStamped],
        planner_id: str = "",
        use_start: bool = False,
    ) -> Any:
        """Send a `ComputePathThroughPoses` action request."""
        if self.compute_path_through_poses_client is None:
            self._unavailable("ComputePathThroughPoses")
            return None
        return self._pathFrom(self._getPathThroughPosesImpl(start, goals, planner_id, use_start))

    def _smoothPathImpl(
        self,
        path: Any,
        smoother_id: str = "",
        max_duration: float = 2.0,
        check_for_collision: bool = False,
    ) -> Any:
        """Send a `SmoothPath` action request; the whole result."""
        if self.smoother_client is None:
            self._unavailable("SmoothPath")
            return None
        goal_msg = SmoothPath.Goal(
            path=path,
            max_smoothing_duration=_duration(float(max_duration)),
            smoother_id=smoother_id,
            check_for_collisions=check_for_collision,
        )
        return self._planResult(
            self.smoother_client,
            goal_msg,
            "SmoothPath",
            "Smoothing path...",
            "Smooth path was rejected!",
        )

    def smoothPath(
        self,
        path: Any,
        smoother_id: str = "",
        max_duration: float = 2.0,
        check_for_collision: bool = False,
    ) -> Any:
        """Send a `SmoothPath` action request."""
        if self.smoother_client is None:
            self._unavailable("SmoothPath")
            return None
        return self._pathFrom(
            self._smoothPathImpl(path, smoother_id, max_duration, check_for_collision)
        )

    # -- maps and costmaps ----------------------------------------------------------------

    def _call(self, client: Any, request: Any, not_available: str) -> Any:
        """Wait for the service (as long as it takes), call it, and block for the answer."""
        while not client.wait_for_service(timeout_sec=1.0):
            self.info(not_available)
        future = client.call_async(request)
        _spin_until_done(self, future)
        return future.result()

    def changeMap(self, map_filepath: str) -> None:
        """Change the current static map in the map server."""
        response = self._call(
            self.change_maps_srv,
            LoadMap.Request(map_url=map_filepath),
            "change map service not available, waiting...",
        )
        if response is None or response.result != LoadMap.Response.RESULT_SUCCESS:
            self.error("Change map request failed!")
        else:
            self.info("Change map request was successful!")

    def clearAllCostmaps(self) -> None:
        """Clear all costmaps."""
        self.clearLocalCostmap()
        self.clearGlobalCostmap()

    def clearLocalCostmap(self) -> None:
        """Clear local costmap."""
        self._call(
            self.clear_costmap_local_srv,
            ClearEntireCostmap.Request(),
            "Clear local costmaps service not available, waiting...",
        )

    def clearGlobalCostmap(self) -> None:
        """Clear global costmap."""
        self._call(
            self.clear_costmap_global_srv,
            ClearEntireCostmap.Request(),
            "Clear global costmaps service not available, waiting...",
        )

    def clearCostmapExceptRegion(self, reset_distance: float) -> None:
        """Clear the costmap except for a specified region."""
        if self.clear_costmap_except_region_srv is None:
            self._unavailable("ClearCostmapExceptRegion")
            return
        self._call(
            self.clear_costmap_except_region_srv,
            ClearCostmapExceptRegion.Request(reset_distance=float(reset_distance)),
            "ClearCostmapExceptRegion service not available, waiting...",
        )

    def clearCostmapAroundRobot(self, reset_distance: float) -> None:
        """Clear the costmap around the robot."""
        if self.clear_costmap_around_robot_srv is None:
            self._unavailable("ClearCostmapAroundRobot")
            return
        self._call(
            self.clear_costmap_around_robot_srv,
            ClearCostmapAroundRobot.Request(reset_distance=float(reset_distance)),
            "ClearCostmapAroundRobot service not available, waiting...",
        )

    def clearCostmapAroundPose(self, pose: PoseStamped, reset_distance: float) -> None:
        """Clear the costmap around a specified pose."""
        if self.clear_costmap_around_pose_srv is None:
            self._unavailable("ClearCostmapAroundPose")
            return
        self._call(
            self.clear_costmap_around_pose_srv,
            ClearCostmapAroundPose.Request(pose=pose, reset_distance=float(reset_distance)),
            "ClearCostmapAroundPose service not available, waiting...",
        )

    def getGlobalCostmap(self) -> Any:
        """Get the global costmap."""
        response = self._call(
            self.get_costmap_global_srv,
            GetCostmap.Request(),
            "Get global costmaps service not available, waiting...",
        )
        return response.map

    def getLocalCostmap(self) -> Any:
        """Get the local costmap."""
        response = self._call(
            self.get_costmap_local_srv,
            GetCostmap.Request(),
            "Get local costmaps service not available, waiting...",
        )
        return response.map

    # -- lifecycle ------------------------------------------------------------------------

    def _lifecycleManagers(self) -> list[str]:
        return [
            name for name, types in self.get_service_names_and_types() if MANAGE_NODES_TYPE in types
        ]

    def lifecycleStartup(self) -> None:
        """Startup nav2 lifecycle system."""
        self.info("Starting up lifecycle nodes based on lifecycle_manager.")
        for srv_name in self._lifecycleManagers():
            self.info(f"Starting up {srv_name}")
            client = self.create_client(ManageLifecycleNodes, srv_name)
            while not client.wait_for_service(timeout_sec=1.0):
                self.info(f"{srv_name} service not available, waiting...")
            future = client.call_async(
                ManageLifecycleNodes.Request(command=ManageLifecycleNodes.Request.STARTUP)
            )
            # Activating needs the whole map -> odom -> base_link tree, which the localizer
            # gives once it has a pose: keep offering it the initial pose until it answers.
            offered = -math.inf
            while not future.done():
                _spin_until_done(self, future, timeout_sec=0.10)
                now = time.monotonic()
                if not future.done() and not self.initial_pose_received and now - offered > 1.0:
                    self._setInitialPose()
                    offered = now
            response = future.result()
            if response is not None and not response.success:
                self.error(f"{srv_name} could not start up every node")
            self.destroy_client(client)
        self.info("Nav2 is ready for use!")

    def lifecycleShutdown(self) -> None:
        """Shutdown nav2 lifecycle system."""
        self.info("Shutting down lifecycle nodes based on lifecycle_manager.")
        for srv_name in self._lifecycleManagers():
            self.info(f"Shutting down {srv_name}")
            client = self.create_client(ManageLifecycleNodes, srv_name)
            self._call(
                client,
                ManageLifecycleNodes.Request(command=ManageLifecycleNodes.Request.SHUTDOWN),
                f"{srv_name} service not available, waiting...",
            )
            self.destroy_client(client)

    def _waitForNodeToActivate(self, node_name: str) -> None:
        """Wait until the lifecycle node ``node_name`` (in our namespace) says it is active."""
        self.debug(f"Waiting for {node_name} to become active..")
        node_service = f"{node_name}/get_state"
        state_client = self.create_client(GetState, node_service)
        while not state_client.wait_for_service(timeout_sec=1.0):
            self.info(f"{node_service} service not available, waiting...")
        state = "unknown"
        while True:
            self.debug(f"Getting {node_name} state...")
            future = state_client.call_async(GetState.Request())
            _spin_until_done(self, future)
            response = future.result()
            if response is not None:
                state = response.current_state.label
                self.debug(f"Result of get_state: {state}")
            if state == "active":
                break
            time.sleep(1.0)
        self.destroy_client(state_client)

    def _waitForInitialPose(self) -> None:
        while not self.initial_pose_received:
            self.info("Setting initial pose")
            self._setInitialPose()
            self.info("Waiting for amcl_pose to be received")
            rclpy.spin_once(self, timeout_sec=1.0)

    def _amclPoseCallback(self, msg: PoseWithCovarianceStamped) -> None:
        self.debug("Received amcl pose")
        self.initial_pose_received = True

    def _feedbackCallback(self, msg: Any) -> None:
        self.debug("Received action feedback message")
        self.feedback = msg.feedback

    def _setInitialPose(self) -> None:
        msg = PoseWithCovarianceStamped()
        msg.header.frame_id = self.initial_pose.header.frame_id
        msg.header.stamp = self.initial_pose.header.stamp
        msg.pose.pose = self.initial_pose.pose
        self.info("Publishing Initial Pose")
        self.initial_pose_pub.publish(msg)

    # -- logging, as Nav2's navigator names it ---------------------------------------------

    def info(self, msg: str) -> None:
        self.get_logger().info(msg)

    def warn(self, msg: str) -> None:
        self.get_logger().warning(msg)

    def error(self, msg: str) -> None:
        self.get_logger().error(msg)

    def debug(self, msg: str) -> None:
        self.get_logger().debug(msg)
