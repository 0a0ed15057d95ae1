"""spin_server: the main() of a Nav2 server that carries nodes of its own (a costmap).

The server and its helper nodes (``costmap_ros``) spin on one
multi-threaded executor, so an action's execute loop may wait while TF and
the map keep arriving. Ctrl+C and SIGTERM end it quietly.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

import rclpy
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor


def spin_server(node_factory: Callable[[], Any], args: list[str] | None, name: str) -> int:
    """Spin a server and its costmap node on one multi-threaded executor until Ctrl+C."""
    node = None
    try:
        try:
            rclpy.init(args=args)
        except Exception as exc:  # rcl refuses the arguments
            print(f"{name}: error: {exc}", file=sys.stderr)
            return 1
        node = node_factory()
        executor = MultiThreadedExecutor(num_threads=6)
        executor.add_node(node)
        costmap = getattr(node, "costmap_ros", None)
        if costmap is not None:
            executor.add_node(costmap)
        try:
            executor.spin()
        finally:
            executor.shutdown(timeout_sec=2.0)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
