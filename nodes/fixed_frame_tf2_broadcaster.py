"""fixed_frame_tf2_broadcaster: the "Adding a frame (Python)" tutorial's fixed carrot.

``carrot1`` sits 2 m to turtle1's left, re-sent on /tf at 10 Hz. Run the
listener with ``target_frame:=carrot1`` and turtle2 follows the carrot.

ROS concepts shown: a frame whose parent is not ``world``: the tree grows.
"""

from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from tf2_ros import TransformBroadcaster

from nodes.common.run import spin_node


class FixedFrameBroadcaster(Node):
    def __init__(self) -> None:
        super().__init__("fixed_frame_tf2_broadcaster")
        self.tf_broadcaster = TransformBroadcaster(self)
        self.timer = self.create_timer(0.1, self.broadcast_timer_callback)

    def broadcast_timer_callback(self) -> None:
        t = TransformStamped()
        t.header.stamp = self.get_clock().now().to_msg()
        t.header.frame_id = "turtle1"
        t.child_frame_id = "carrot1"
        t.transform.translation.x = 0.0
        t.transform.translation.y = 2.0
        t.transform.translation.z = 0.0
        t.transform.rotation.x = 0.0
        t.transform.rotation.y = 0.0
        t.transform.rotation.z = 0.0
        t.transform.rotation.w = 1.0
        self.tf_broadcaster.sendTransform(t)


def main(args=None) -> None:
    spin_node(FixedFrameBroadcaster, args)


if __name__ == "__main__":
    main()
