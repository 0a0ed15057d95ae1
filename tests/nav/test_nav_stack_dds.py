"""The office_navigation launch group driven by Nav2's own Python API, as a learner's script is.

Every member of the group as the dashboard starts it (the office world with
no world -> odom, its robot_state_publisher, map_server with the office map,
amcl told where the robot starts, the planner, controller and navigator,
brought up by the lifecycle manager); then nav2_simple_commander's
BasicNavigator, in this process, waits for Nav2 to be active, plans a path
and drives the robot through a door into the meeting room. amcl is what
tells TF where the robot is on the map: the goal is reached only if
localization, planning and control all work together.
"""

from __future__ import annotations

import math
import time

import pytest
import rclpy
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult

from app.catalog import lookup_group
from tests.nav.commander_helpers import Truth, in_thread, map_pose

pytestmark = [pytest.mark.ros, pytest.mark.timeout(300)]

FASTER = ("-p", "camera_rate:=0.0", "-p", "real_time_factor:=2.0")  # the world's members only
GOAL = (4.0, 1.7, math.pi / 2)  # the meeting room, through its door at x = 3.7..4.6
# m: the goal checker's 0.25 plus what amcl may be off (a loaded run ended 0.48 m away:
# amcl dropped scans while the cores were busy)
REACHED = 0.6


def test_basic_navigator_drives_the_office_robot_through_a_door(ros_env, supervisor):
    started = time.monotonic()
    group = lookup_group("office_navigation")
    for member in group.members:
        supervisor.start(member, FASTER if member.startswith("sim_office") else ())

    def logs() -> str:
        return "\n".join(
            f"--- {name}\n" + "\n".join(supervisor.output(name)[-15:]) for name in group.members
        )

    rclpy.init()
    nav = BasicNavigator()
    truth = Truth(nav)
    try:
        in_thread(nav.waitUntilNav2Active, 120, "Nav2 did not become active", logs)
        up = time.monotonic() - started

        path = nav.getPath(map_pose(nav, 0.0, 0.0, 0.0), map_pose(nav, *GOAL), use_start=True)
        assert path is not None and len(path.poses) > 20, logs()

        driving = time.monotonic()
        assert nav.goToPose(map_pose(nav, *GOAL)), logs()
        distances: list[float] = []

        def until_done() -> None:
            while not nav.isTaskComplete():
                feedback = nav.getFeedback()
                if feedback is not None and feedback.distance_remaining > 0:
                    distances.append(feedback.distance_remaining)

        in_thread(until_done, 150, "the navigation did not end", logs)
        drive = time.monotonic() - driving
        assert nav.getResult() == TaskResult.SUCCEEDED, logs()
        x, y = truth.now()
        assert math.hypot(x - GOAL[0], y - GOAL[1]) < REACHED, (x, y, logs())
        assert distances and distances[0] > 3.0, distances[:5]
        for name in group.members:
            assert supervisor.status(name).active, (name, logs())
            assert "Traceback" not in "\n".join(supervisor.output(name)), logs()
        print(
            f"\nNav2 active {up:.1f} s after the start, drive {drive:.1f} s wall, "
            f"ended {math.hypot(x - GOAL[0], y - GOAL[1]):.2f} m from the goal"
        )
    finally:
        nav.destroyNode()
        rclpy.try_shutdown()
