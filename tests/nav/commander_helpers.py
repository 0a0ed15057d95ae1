"""What the tests that drive Nav2 with BasicNavigator share: a map pose, a deadline, the truth."""

from __future__ import annotations

import math
import threading
import time
from typing import Any

import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator
from nav_msgs.msg import Odometry


def map_pose(nav: BasicNavigator, x: float, y: float, yaw: float) -> PoseStamped:
    """A pose on the map (frame ``map``), stamped now, facing ``yaw``."""
    pose = PoseStamped()
    pose.header.frame_id = "map"
    pose.header.stamp = nav.get_clock().now().to_msg()
    pose.pose.position.x, pose.pose.position.y = x, y
    pose.pose.orientation.z, pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return pose


def in_thread(work: Any, timeout: float, what: str, logs: Any) -> None:
    """Run a blocking commander call (it waits forever, as upstream's do) with a deadline."""
    failure: list[BaseException] = []

    def run() -> None:
        try:
            work()
        except BaseException as exc:  # carried to the test's thread
            failure.append(exc)

    worker = threading.Thread(target=run, daemon=True)
    worker.start()
    worker.join(timeout)
    assert not worker.is_alive(), f"{what} after {timeout:.0f} s\n{logs()}"
    if failure:
        raise failure[0]


class Truth:
    """The simulator's /ground_truth/odom, taken on the navigator's own node."""

    def __init__(self, nav: BasicNavigator) -> None:
        self.nav = nav
        self.pose: tuple[float, float] | None = None
        self.speed = 0.0
        self.heard_at = 0.0  # when the last message was taken (this clock)
        nav.create_subscription(Odometry, "/ground_truth/odom", self.on_odom, 10)

    def on_odom(self, msg: Odometry) -> None:
        self.pose = (msg.pose.pose.position.x, msg.pose.pose.position.y)
        self.speed = math.hypot(msg.twist.twist.linear.x, msg.twist.twist.linear.y)
        self.heard_at = time.monotonic()

    def now(self) -> tuple[float, float]:
        """Where the robot is now: the pose of a message taken after this call. The node is
        spun only while a task runs, so the last pose taken may be from before a stall of this
        process (a loaded run read the robot 0.8 m short of the goal the controller had reached)."""
        asked = time.monotonic()
        while self.heard_at <= asked:
            assert time.monotonic() - asked < 10, "no /ground_truth/odom for 10 s"
            rclpy.spin_once(self.nav, timeout_sec=0.05)
        assert self.pose is not None
        return self.pose
