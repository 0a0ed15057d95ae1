"""What the tests that drive Nav2 with BasicNavigator share: a map pose, a deadline."""

from __future__ import annotations

import math
import threading
from typing import Any

from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator


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
