"""StaticTransformBroadcaster: latched transforms on /tf_static.

The topic is transient local, so a node that starts later still receives
every static frame. One message carries all frames this broadcaster ever
sent (a new one for a known child replaces the old), because a late joiner
gets only the last message.
"""

from __future__ import annotations

from collections.abc import Iterable

from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile
from tf2_msgs.msg import TFMessage


class StaticTransformBroadcaster:
    """Publishes the accumulated static frames on ``/tf_static`` (transient local, depth 1)."""

    def __init__(self, node: Node, qos: QoSProfile | int | None = None) -> None:
        if qos is None:
            qos = QoSProfile(
                depth=1,
                durability=DurabilityPolicy.TRANSIENT_LOCAL,
                history=HistoryPolicy.KEEP_LAST,
            )
        self.pub_tf = node.create_publisher(TFMessage, "/tf_static", qos)
        self.net_message = TFMessage()
        self._index: dict[str, int] = {}

    def sendTransform(self, transform: TransformStamped | Iterable[TransformStamped]) -> None:
        transforms = [transform] if isinstance(transform, TransformStamped) else list(transform)
        for t_in in transforms:
            at = self._index.get(t_in.child_frame_id)
            if at is None:
                self._index[t_in.child_frame_id] = len(self.net_message.transforms)
                self.net_message.transforms.append(t_in)
            else:
                self.net_message.transforms[at] = t_in
        self.pub_tf.publish(self.net_message)
