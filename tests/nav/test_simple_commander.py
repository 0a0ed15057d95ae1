"""Nav2's Simple Commander (nav2_simple_commander.BasicNavigator) against servers on Nav2's names.

The servers are small stand-ins (fake_nav2_servers.py: real rclpy action
servers and services with the real nav2_msgs interfaces, in a node and rclpy
context of their own); the navigator talks to them over DDS as a learner's
script talks to Nav2. Checked as a learner sees it: what each call returns,
the feedback and results, the log lines Nav2 prints, and what the servers
were sent. This file imports nothing of the project but nav2_simple_commander.
"""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from collections.abc import Iterator

import pytest
import rclpy
from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped
from lifecycle_msgs.msg import State
from nav2_msgs.srv import ManageLifecycleNodes
from nav2_simple_commander.costmap_2d import PyCostmap2D
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult
from nav_msgs.msg import OccupancyGrid
from nav_msgs.msg import Path as NavPath

from tests.nav.fake_nav2_servers import ABORT, MANAGERS, UNTIL_CANCELED, FakeNav2, wait_for

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

TASK_TIMEOUT = 30.0  # generous: a CI rehearsal may share the machine


@pytest.fixture
def nav2(ros_env) -> Iterator[FakeNav2]:
    fake = FakeNav2()
    yield fake
    fake.close()


@pytest.fixture
def navigator(nav2) -> Iterator[BasicNavigator]:
    """A BasicNavigator as a learner's script makes one: rclpy.init() and the default context."""
    rclpy.init()
    nav = BasicNavigator()
    yield nav
    nav.destroy_node()
    rclpy.try_shutdown()


def pose(x: float, y: float) -> PoseStamped:
    msg = PoseStamped()
    msg.header.frame_id = "map"
    msg.pose.position.x = x
    msg.pose.position.y = y
    msg.pose.orientation.w = 1.0
    return msg


def until_complete(nav: BasicNavigator) -> list:
    """Poll isTaskComplete() as Nav2's examples do; the distinct feedback seen on the way."""
    seen: list = []
    deadline = time.monotonic() + TASK_TIMEOUT
    while not nav.isTaskComplete():
        feedback = nav.getFeedback()
        if feedback is not None and (not seen or feedback is not seen[-1]):
            seen.append(feedback)
        assert time.monotonic() < deadline, "the task never completed"
    return seen


def test_go_to_pose_feedback_and_success(navigator, nav2, capfd):
    assert navigator.isTaskComplete()  # nothing sent yet
    assert navigator.getResult() == TaskResult.UNKNOWN
    assert navigator.goToPose(pose(1.5, -2.0), behavior_tree="/trees/my_tree.xml") is True
    feedback = until_complete(navigator)
    assert navigator.getResult() == TaskResult.SUCCEEDED
    assert navigator.status == GoalStatus.STATUS_SUCCEEDED
    # the server got the pose and the behaviour tree
    (goal,) = nav2.goals["navigate_to_pose"]
    assert (goal.pose.pose.position.x, goal.pose.pose.position.y) == (1.5, -2.0)
    assert goal.pose.header.frame_id == "map"
    assert goal.behavior_tree == "/trees/my_tree.xml"
    # NavigateToPose feedback, in order, as the server sent it
    assert feedback, "no feedback arrived"
    distances = [f.distance_remaining for f in feedback]
    assert distances == sorted(distances, reverse=True)
    assert navigator.getFeedback().distance_remaining == pytest.approx(6.0)
    assert "Navigating to goal: 1.5 -2.0..." in capfd.readouterr().err


def test_a_rejected_goal_returns_false(navigator, nav2, capfd):
    assert navigator.goToPose(pose(-1.0, 0.0)) is False
    assert "Goal to -1.0 0.0 was rejected!" in capfd.readouterr().err
    assert len(nav2.goals["navigate_to_pose"]) == 1


def test_an_aborted_task_fails(navigator, nav2):
    nav2.mode["navigate_through_poses"] = ABORT
    assert navigator.goThroughPoses([pose(1.0, 0.0), pose(2.0, 1.0)]) is True
    until_complete(navigator)
    assert navigator.getResult() == TaskResult.FAILED
    assert navigator.status == GoalStatus.STATUS_ABORTED
    (goal,) = nav2.goals["navigate_through_poses"]
    assert [p.pose.position.x for p in goal.poses] == [1.0, 2.0]


def test_cancel_task(navigator, nav2, capfd):
    nav2.mode["navigate_to_pose"] = UNTIL_CANCELED
    assert navigator.goToPose(pose(3.0, 1.0))
    deadline = time.monotonic() + TASK_TIMEOUT
    while navigator.getFeedback() is None:  # running: feedback flows while we poll
        assert not navigator.isTaskComplete()
        assert time.monotonic() < deadline, "no feedback while the task ran"
    navigator.cancelTask()
    until_complete(navigator)
    assert navigator.getResult() == TaskResult.CANCELED
    assert nav2.canceled == ["navigate_to_pose"]
    assert "Canceling current task." in capfd.readouterr().err


def test_polling_a_long_task_leaves_no_work_behind(navigator, nav2):
    """Polled for seconds, a task must not leave wake-ups behind that later turn the
    executor round and round without waiting. rclpy 7.1's spin_until_future_complete
    adds a done callback at every turn, and each becomes a task when the future ends
    (ros2/rclpy#1374): a navigator that polls and plans again and again spun a core."""
    nav2.mode["navigate_to_pose"] = UNTIL_CANCELED
    assert navigator.goToPose(pose(3.0, 1.0))
    deadline = time.monotonic() + 3.0
    while time.monotonic() < deadline:  # feedback flows at 10 Hz meanwhile
        assert not navigator.isTaskComplete()
    navigator.cancelTask()
    until_complete(navigator)
    executor = rclpy.get_global_executor()
    turns = 0
    turn = executor._spin_once_impl

    def counted(*args, **kwargs):
        nonlocal turns
        turns += 1
        return turn(*args, **kwargs)

    executor._spin_once_impl = counted
    try:
        assert isinstance(navigator.getPath(pose(0.0, 0.0), pose(2.0, 1.0)), NavPath)
    finally:
        del executor._spin_once_impl
    # A plan is a goal answer, a status or two and a result: a handful of turns.
    assert turns <= 15, f"{turns} turns of the executor for one plan"


def test_waypoints_paths_and_behaviours(navigator, nav2, capfd):
    """followWaypoints, followPath, spin, backup and driveOnHeading send Nav2's goals."""
    assert navigator.followWaypoints([pose(1.0, 1.0), pose(2.0, 2.0), pose(3.0, 1.0)])
    feedback = until_complete(navigator)
    assert navigator.getResult() == TaskResult.SUCCEEDED
    assert len(nav2.goals["follow_waypoints"][0].poses) == 3
    assert {f.current_waypoint for f in feedback} <= {0, 1, 2, 3, 4}

    path = NavPath()
    path.header.frame_id = "map"
    path.poses = [pose(0.0, 0.0), pose(1.0, 0.0)]
    assert navigator.followPath(path, controller_id="FollowPath", goal_checker_id="precise")
    until_complete(navigator)
    assert navigator.getResult() == TaskResult.SUCCEEDED
    (goal,) = nav2.goals["follow_path"]
    assert (goal.controller_id, goal.goal_checker_id, len(goal.path.poses)) == (
        "FollowPath",
        "precise",
        2,
    )

    assert navigator.spin(spin_dist=3.14, time_allowance=7)
    until_complete(navigator)
    goal = nav2.goals["spin"][0]
    assert (goal.target_yaw, goal.time_allowance.sec) == (pytest.approx(3.14), 7)

    assert navigator.backup(backup_dist=0.3, backup_speed=0.05)
    until_complete(navigator)
    goal = nav2.goals["backup"][0]
    assert (goal.target.x, goal.speed, goal.time_allowance.sec) == (
        pytest.approx(0.3),
        pytest.approx(0.05),
        10,
    )

    assert navigator.driveOnHeading(dist=0.5, speed=0.1, time_allowance=4)
    until_complete(navigator)
    assert navigator.getResult() == TaskResult.SUCCEEDED
    goal = nav2.goals["drive_on_heading"][0]
    assert (goal.target.x, goal.speed, goal.time_allowance.sec) == (
        pytest.approx(0.5),
        pytest.approx(0.1),
        4,
    )
    err = capfd.readouterr().err
    for line in (
        "Following 3 goals....",
        "Executing path...",
        "Spinning to angle 3.14",
        "Backing up 0.3 m at 0.05",
        "Drive 0.5 m on heading at 0.1",
    ):
        assert line in err, line


def test_get_path(navigator, nav2, capfd):
    path = navigator.getPath(pose(0.0, 0.0), pose(2.0, 1.0), planner_id="GridBased", use_start=True)
    assert isinstance(path, NavPath)
    (planned,) = nav2.planned
    assert [(p.pose.position.x, p.pose.position.y) for p in path.poses] == [
        (p.pose.position.x, p.pose.position.y) for p in planned.poses
    ]
    (goal,) = nav2.goals["compute_path_to_pose"]
    assert (goal.planner_id, goal.use_start) == ("GridBased", True)
    # a goal the planner cannot reach: None, and Nav2's warning with the status code
    assert navigator.getPath(pose(0.0, 0.0), pose(-5.0, 0.0)) is None
    assert f"Getting path failed with status code: {GoalStatus.STATUS_ABORTED}" in (
        capfd.readouterr().err
    )


def test_wait_until_nav2_active(navigator, nav2, capfd):
    """Waits for amcl to be active, for amcl_pose after the initial pose, then bt_navigator."""
    nav2.states["amcl"] = State.PRIMARY_STATE_INACTIVE
    nav2.states["bt_navigator"] = State.PRIMARY_STATE_INACTIVE
    start = pose(0.5, -0.25)
    start.pose.orientation.z, start.pose.orientation.w = 0.6, 0.8
    navigator.setInitialPose(start)
    done = threading.Event()

    def wait_until_active() -> None:
        navigator.waitUntilNav2Active()
        done.set()

    waiter = threading.Thread(target=wait_until_active)
    waiter.start()
    try:
        assert not done.wait(2.5), "returned while amcl was inactive"
        nav2.states["amcl"] = State.PRIMARY_STATE_ACTIVE
        # active amcl now answers the initial pose (published again each second) with amcl_pose
        wait_for(lambda: navigator.initial_pose_received, TASK_TIMEOUT, "amcl_pose")
        assert not done.wait(2.0), "returned while bt_navigator was inactive"
        nav2.states["bt_navigator"] = State.PRIMARY_STATE_ACTIVE
        assert done.wait(TASK_TIMEOUT), "never saw bt_navigator active"
    finally:
        nav2.states["amcl"] = nav2.states["bt_navigator"] = State.PRIMARY_STATE_ACTIVE
        waiter.join(TASK_TIMEOUT)
    assert not waiter.is_alive()
    # /initialpose carried the pose as given
    sent = nav2.initial_poses[-1]
    assert sent.header.frame_id == "map"
    assert (sent.pose.pose.position.x, sent.pose.pose.position.y) == (0.5, -0.25)
    assert (sent.pose.pose.orientation.z, sent.pose.pose.orientation.w) == (0.6, 0.8)
    err = capfd.readouterr().err
    assert "Publishing Initial Pose" in err
    assert "Nav2 is ready for use!" in err


def test_maps_and_costmaps(navigator, nav2, capfd):
    navigator.changeMap("/home/learner/maps/office.yaml")
    assert "Change map request was successful!" in capfd.readouterr().err
    navigator.changeMap("/home/learner/maps/nowhere.pgm")
    assert "Change map request failed!" in capfd.readouterr().err
    assert nav2.calls["load_map"] == [
        "/home/learner/maps/office.yaml",
        "/home/learner/maps/nowhere.pgm",
    ]

    navigator.clearAllCostmaps()
    assert len(nav2.calls["clear local_costmap"]) == 1
    assert len(nav2.calls["clear global_costmap"]) == 1
    navigator.clearGlobalCostmap()
    assert len(nav2.calls["clear global_costmap"]) == 2

    costmap = navigator.getGlobalCostmap()
    assert (costmap.header.frame_id, costmap.metadata.size_x, costmap.metadata.size_y) == (
        "map",
        3,
        2,
    )
    assert list(costmap.data) == [0, 0, 254, 0, 253, 255]
    assert navigator.getLocalCostmap().header.frame_id == "odom"


def test_lifecycle_startup_and_shutdown(navigator, nav2, capfd):
    """Every ManageLifecycleNodes service in the graph gets STARTUP, then SHUTDOWN."""
    wanted = {f"/{manager}/manage_nodes" for manager in MANAGERS}
    wait_for(
        lambda: wanted <= {name for name, _ in navigator.get_service_names_and_types()},
        TASK_TIMEOUT,
        "the lifecycle managers in the graph",
    )
    nav2.states["amcl"] = nav2.states["bt_navigator"] = State.PRIMARY_STATE_INACTIVE
    navigator.lifecycleStartup()
    for manager in MANAGERS:
        assert nav2.calls[manager] == [ManageLifecycleNodes.Request.STARTUP]
    assert nav2.states["bt_navigator"] == State.PRIMARY_STATE_ACTIVE
    navigator.lifecycleShutdown()
    for manager in MANAGERS:
        assert nav2.calls[manager] == [
            ManageLifecycleNodes.Request.STARTUP,
            ManageLifecycleNodes.Request.SHUTDOWN,
        ]
    err = capfd.readouterr().err
    assert "Starting up lifecycle nodes based on lifecycle_manager." in err
    assert "Shutting down /lifecycle_manager_navigation/manage_nodes" in err


def test_methods_without_an_interface_say_so(navigator, capfd):
    """Nav2 interfaces our nav2_msgs lacks: an error naming it, and Nav2's failure value."""
    start, goals = pose(0.0, 0.0), [pose(1.0, 0.0)]
    assert navigator.getPathThroughPoses(start, goals) is None
    assert navigator.smoothPath(NavPath()) is None
    assert navigator.assistedTeleop() is False
    assert navigator.dockRobotByID("dock1") is False
    assert navigator.dockRobotByPose(start, "charger") is False
    assert navigator.undockRobot("charger") is False
    assert navigator.followGpsWaypoints([]) is False
    navigator.clearCostmapAroundRobot(1.0)
    err = capfd.readouterr().err
    for interface in ("ComputePathThroughPoses", "SmoothPath", "AssistedTeleop", "DockRobot"):
        assert f"'{interface}' is not available" in err, interface
    assert "'ClearCostmapAroundRobot' is not available" in err


def test_the_example_script_runs_unchanged(nav2, ros_env):
    """Nav2's example, as a learner runs it: its own process, its own rclpy.init()."""
    done = subprocess.run(
        [sys.executable, "-m", "nav2_simple_commander.example_nav_to_pose", "1.5", "0.5"],
        env=ros_env,
        capture_output=True,
        text=True,
        timeout=90,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Goal succeeded!" in done.stdout, done.stdout + done.stderr
    assert "Nav2 is ready for use!" in done.stderr
    (goal,) = nav2.goals["navigate_to_pose"]
    assert (goal.pose.pose.position.x, goal.pose.pose.position.y) == (1.5, 0.5)
    assert nav2.initial_poses, "the example never published /initialpose"


def test_py_costmap_2d_reads_a_published_costmap():
    """PyCostmap2D on an OccupancyGrid as a costmap publishes it (no DDS needed)."""
    grid = OccupancyGrid()
    grid.header.frame_id = "map"
    grid.info.width, grid.info.height, grid.info.resolution = 4, 3, 0.5
    grid.info.origin.position.x, grid.info.origin.position.y = -1.0, 2.0
    grid.data = [0, 1, 2, 3, 10, 11, 12, 13, 99, 100, -1, 50]  # bottom row first
    costmap = PyCostmap2D(grid)
    assert (costmap.getSizeInCellsX(), costmap.getSizeInCellsY()) == (4, 3)
    assert costmap.getSizeInMetersX() == pytest.approx(1.75)
    assert (costmap.getOriginX(), costmap.getOriginY(), costmap.getResolution()) == (-1.0, 2.0, 0.5)
    assert costmap.getGlobalFrameID() == "map"
    assert costmap.getIndex(1, 2) == 9
    assert costmap.getCostXY(1, 2) == 100
    assert costmap.getCostXY(2, 2) == 255  # unknown
    assert costmap.getCostIdx(5) == 11
    costmap.setCost(0, 0, 254)
    assert costmap.getCostXY(0, 0) == 254
    assert costmap.mapToWorld(1, 2) == (pytest.approx(-0.25), pytest.approx(3.25))
    assert costmap.worldToMapValidated(-0.25, 3.25) == (1, 2)
    assert costmap.worldToMapValidated(-1.5, 2.5) == (None, None)  # left of the origin
    assert costmap.worldToMapValidated(1.1, 2.5) == (None, None)  # past the last column
