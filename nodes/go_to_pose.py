"""go_to_pose: send the robot to a point of the map with Nav2's Python API.

``ros2 run tutorial_nodes go_to_pose X Y``: the few lines a Nav2 user writes
with nav2_simple_commander's BasicNavigator (our Python version, the same
API as Nav2's): wait until Nav2 is active, send one goal, print how far is
left now and then, and say how it ended. Unlike Nav2's example_nav_to_pose
it sets no initial pose: amcl already knows where the robot is, and telling
it the robot is at the origin when it is not would lose it.
"""

from __future__ import annotations

import math
import sys
import time

import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult
from rclpy.executors import ExternalShutdownException

from nodes.common.run import run_program


def main(argv: list[str] | None = None) -> int:
    words = rclpy.utilities.remove_ros_args(sys.argv if argv is None else argv)[1:]
    try:
        x, y = (float(words[0]), float(words[1])) if words else (0.0, 0.0)
    except (ValueError, IndexError):
        print("go_to_pose: error: give the goal as two numbers, X Y (metres)", file=sys.stderr)
        return 2
    rclpy.init(args=argv)
    navigator = BasicNavigator()
    try:
        # amcl's pose is latched: once it arrives, the navigator knows amcl is localized.
        # Without it, waitUntilNav2Active would first publish its default initial pose (the
        # map's origin), as Nav2's does, and lose a robot that stands somewhere else.
        deadline = time.monotonic() + 3.0
        while not navigator.initial_pose_received and time.monotonic() < deadline:
            rclpy.spin_once(navigator, timeout_sec=0.2)
        navigator.waitUntilNav2Active()  # amcl and bt_navigator active

        goal = PoseStamped()
        goal.header.frame_id = "map"
        goal.header.stamp = navigator.get_clock().now().to_msg()
        goal.pose.position.x, goal.pose.position.y = x, y
        goal.pose.orientation.w = 1.0  # facing +x at the end
        if not navigator.goToPose(goal):
            print("Goal was rejected!")
            return 1

        last_said = math.inf
        while not navigator.isTaskComplete():
            feedback = navigator.getFeedback()
            if feedback is not None and feedback.distance_remaining < last_said - 1.0:
                last_said = feedback.distance_remaining
                print(f"{last_said:.1f} m to go", flush=True)

        result = navigator.getResult()
        words_for = {
            TaskResult.SUCCEEDED: "Goal succeeded!",
            TaskResult.CANCELED: "Goal was canceled!",
            TaskResult.FAILED: "Goal failed!",
        }
        print(words_for.get(result, "Goal has an invalid return status!"), flush=True)
        return 0 if result == TaskResult.SUCCEEDED else 1
    except (KeyboardInterrupt, ExternalShutdownException):
        return 0  # stopped on request (Ctrl+C, SIGTERM), as any node
    finally:
        navigator.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it quietly, even while it starts
