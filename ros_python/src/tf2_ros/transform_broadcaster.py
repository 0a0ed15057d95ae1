"""TransformBroadcaster: send dynamic transforms on /tf."""

from __future__ import annotations

from collections.abc import Iterable

from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from rclpy.qos import QoSProfile
from tf2_msgs.msg import TFMessage


class TransformBroadcaster:
    """Publishes ``TFMessage`` on ``/tf`` (keep last 100, as upstream)."""

    def __init__(self, node: Node, qos: QoSProfile | int | None = None) -> None:
        if qos is None:
            qos = QoSProfile(depth=100)
        self.pub_tf = node.create_publisher(TFMessage, "/tf", qos)

    def sendTransform(self, transform: TransformStamped | Iterable[TransformStamped]) -> None:
        """Send one transform or several in one message."""
        if isinstance(transform, TransformStamped):
            transforms = [transform]
        else:
            transforms = list(transform)
        self.pub_tf.publish(TFMessage(transforms=transforms))
