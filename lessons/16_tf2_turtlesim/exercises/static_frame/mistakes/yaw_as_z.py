"""Mistake: yaw written into the quaternion's z as it is, with w = 1."""

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tf2_ros import StaticTransformBroadcaster

NAMES = ("parent_frame", "child_frame", "x", "y", "z", "yaw")


class FrameAnnouncer(Node):
    def __init__(self):
        super().__init__("frame_announcer")
        self.declare_parameter("parent_frame", "world")
        self.declare_parameter("child_frame", "sensor")
        for axis in ("x", "y", "z", "yaw"):
            self.declare_parameter(axis, 0.0)
        self.broadcaster = StaticTransformBroadcaster(self)
        self.sent = None
        self.timer = self.create_timer(0.5, self.send_if_changed)
        self.send_if_changed()

    def send_if_changed(self):
        values = {name: self.get_parameter(name).value for name in NAMES}
        if values != self.sent:
            self.send(values)
            self.sent = values

    def send(self, values):
        t = TransformStamped()
        t.header.stamp = self.get_clock().now().to_msg()
        t.header.frame_id = values["parent_frame"]
        t.child_frame_id = values["child_frame"]
        t.transform.translation.x = float(values["x"])
        t.transform.translation.y = float(values["y"])
        t.transform.translation.z = float(values["z"])
        t.transform.rotation.z = float(values["yaw"])
        t.transform.rotation.w = 1.0
        self.broadcaster.sendTransform(t)
        self.get_logger().info(f"sent {values['parent_frame']} -> {values['child_frame']}")


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
