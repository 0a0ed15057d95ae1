"""Accepted, written differently: no polling timer; the frame is sent again from a
post-set-parameters callback."""

import math

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tf2_ros import StaticTransformBroadcaster


class FrameAnnouncer(Node):
    def __init__(self):
        super().__init__("frame_announcer")
        self.declare_parameters(
            "",
            [
                ("parent_frame", "world"),
                ("child_frame", "sensor"),
                ("x", 0.0),
                ("y", 0.0),
                ("z", 0.0),
                ("yaw", 0.0),
            ],
        )
        self.broadcaster = StaticTransformBroadcaster(self)
        self.add_post_set_parameters_callback(lambda _params: self.send())
        self.send()

    def send(self):
        get = lambda name: self.get_parameter(name).value  # noqa: E731
        t = TransformStamped()
        t.header.stamp = self.get_clock().now().to_msg()
        t.header.frame_id, t.child_frame_id = get("parent_frame"), get("child_frame")
        t.transform.translation.x = float(get("x"))
        t.transform.translation.y = float(get("y"))
        t.transform.translation.z = float(get("z"))
        t.transform.rotation.z = math.sin(get("yaw") / 2)
        t.transform.rotation.w = math.cos(get("yaw") / 2)
        self.broadcaster.sendTransform(t)


def main():
    rclpy.init()
    node = FrameAnnouncer()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
