"""Subscription QoS that matches whoever publishes, as ``ros2 topic echo`` does.

A best-effort subscriber hears everyone, but then big messages (a 1.6 MB
cloud is ~25 UDP fragments) are lost whole when one fragment is; a reliable
subscriber repairs that but cannot hear best-effort publishers. So we look at
the publishers on the graph and ask for reliable delivery only when every one
of them offers it. Depth 1: the scene only ever wants the newest message.
"""

from __future__ import annotations

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.qos import QoSProfile

from app.ros.qos import matching_qos


def newest_only_qos(node: Node, topic: str) -> QoSProfile:
    return matching_qos(node, topic, depth=1, latched=False)


# The scene's callbacks only drop a message into a box, so they may run
# alongside each other and alongside the other panels' callbacks: a slow
# callback elsewhere in the dashboard must not hold up the 3D view.
SCENE_CALLBACK_GROUP = ReentrantCallbackGroup()
