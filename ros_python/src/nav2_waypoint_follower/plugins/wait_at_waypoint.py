"""WaitAtWaypoint: the task executor that pauses the robot at each waypoint it reaches.

As Nav2's ``nav2_waypoint_follower::WaitAtWaypoint``: its parameters live
under the plugin's name on the follower node, ``<name>.waypoint_pause_duration``
(milliseconds, 0: the plugin disables itself) and ``<name>.enabled``.
"""

from __future__ import annotations

from typing import Any

from rclpy.duration import Duration

PLUGIN_TYPE = "nav2_waypoint_follower::WaitAtWaypoint"


class WaitAtWaypoint:
    def __init__(self) -> None:
        self.waypoint_pause_duration = 0  # ms
        self.is_enabled = True
        self.node: Any = None

    def initialize(self, node: Any, plugin_name: str) -> None:
        self.node = node
        for name, default in (("waypoint_pause_duration", 0), ("enabled", True)):
            if not node.has_parameter(f"{plugin_name}.{name}"):
                node.declare_parameter(f"{plugin_name}.{name}", default)
        self.waypoint_pause_duration = int(
            node.get_parameter(f"{plugin_name}.waypoint_pause_duration").value
        )
        self.is_enabled = bool(node.get_parameter(f"{plugin_name}.enabled").value)
        if self.waypoint_pause_duration == 0:
            self.is_enabled = False
            node.get_logger().info(
                "Waypoint pause duration is set to zero, disabling task executor plugin."
            )
        elif not self.is_enabled:
            node.get_logger().info("Waypoint task executor plugin is disabled.")

    def process_at_waypoint(self, pose: Any, index: int) -> bool:
        """Pause ``waypoint_pause_duration`` ms on the node's clock; True: the task is done."""
        if not self.is_enabled:
            return True
        self.node.get_logger().info(
            f"Arrived at {index}'th waypoint, sleeping for "
            f"{self.waypoint_pause_duration} milliseconds"
        )
        self.node.get_clock().sleep_for(Duration(nanoseconds=self.waypoint_pause_duration * 10**6))
        return True
