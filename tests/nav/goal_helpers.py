"""What the navigation DDS tests share: a goal pose, waiting on a future, a node's parameter."""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import Any

from geometry_msgs.msg import PoseStamped
from rcl_interfaces.srv import GetParameters
from rclpy.node import Node
from rclpy.parameter import parameter_value_to_python


def pose_stamped(x: float, y: float, yaw: float) -> PoseStamped:
    """A pose in the map frame, facing ``yaw`` (rad)."""
    pose = PoseStamped()
    pose.header.frame_id = "map"
    pose.pose.position.x, pose.pose.position.y = x, y
    pose.pose.orientation.z, pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return pose


def wait_future(future: Any, timeout: float, what: str | Callable[[], str]) -> Any:
    """The future's result, failing with ``what`` (called only then) if it is not done in time."""
    done = threading.Event()
    future.add_done_callback(lambda _f: done.set())
    assert done.wait(timeout), what() if callable(what) else what
    return future.result()


def parameter(node: Node, fqn: str, name: str, timeout: float = 10.0) -> Any:
    """A running node's parameter as a Python value, asked over its parameter service (not
    its log, which a busy node's warnings can push out of the supervisor's ring of lines)."""
    client = node.create_client(GetParameters, f"{fqn}/get_parameters")
    try:
        assert client.wait_for_service(timeout_sec=timeout), f"{fqn} offers no parameters"
        future = client.call_async(GetParameters.Request(names=[name]))
        (value,) = wait_future(future, timeout, f"{fqn} did not answer for {name!r}").values
        return parameter_value_to_python(value)
    finally:
        node.destroy_client(client)
