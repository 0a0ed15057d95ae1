"""dynamic_frame_tf2_broadcaster: the "Adding a frame (Python)" tutorial's moving carrot.

``carrot1`` circles turtle1 at 10 m, its offset changing with the clock,
re-sent on /tf at 10 Hz.

ROS concepts shown: a child frame whose transform changes over time.
"""

import math

from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from tf2_ros import TransformBroadcaster

from nodes.common.run import spin_node


class DynamicFrameBroadcaster(Node):
    def __init__(self) -> None:
        super().__init__("dynamic_frame_tf2_broadcaster")
        self.tf_broadcaster = TransformBroadcaster(self)
        self.timer = self.create_timer(0.1, self.broadcast_timer_callback)

    def broadcast_timer_callback(self) -> None:
        seconds, _ = self.get_clock().now().seconds_nanoseconds()
        x = seconds * math.pi
        t = TransformStamped()
        t.header.stamp = self.get_clock().now().to_msg()
        t.header.frame_id = "turtle1"
        t.child_frame_id = "carrot1"
        t.transform.translation.x = 10 * math.sin(x)
        t.transform.translation.y = 10 * math.cos(x)
        t.transform.translation.z = 0.0
        t.transform.rotation.x = 0.0
        t.transform.rotation.y = 0.0
        t.transform.rotation.z = 0.0
        t.transform.rotation.w = 1.0
        self.tf_broadcaster.sendTransform(t)


def main(args=None) -> None:
    spin_node(DynamicFrameBroadcaster, args)


if __name__ == "__main__":
    main()
