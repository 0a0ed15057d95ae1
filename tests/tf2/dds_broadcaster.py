"""A broadcaster process for test_tf2_outside.py: 12 static frames, one moving frame.

Static frames s0..s11 form a chain under ``world`` (each sent by its own
``sendTransform`` call, so a late joiner sees all of them only if the
broadcaster accumulates); ``moving`` slides along x at 1 m/s on /tf at 50 Hz.
Imports only tf2_ros and rclpy. Prints READY once every static frame is out.
"""

from __future__ import annotations

import math

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tf2_ros import StaticTransformBroadcaster, TransformBroadcaster

STATIC_COUNT = 12


def static_offset(k: int) -> tuple[float, float, float, float]:
    """(x, y, z, yaw) of s<k> in its parent: a little different for each frame."""
    return (0.1 * (k + 1), -0.05 * k, 0.02, 0.1 * k)


class Broadcaster(Node):
    def __init__(self) -> None:
        super().__init__("outside_broadcaster")
        self.static_broadcaster = StaticTransformBroadcaster(self)
        for k in range(STATIC_COUNT):
            x, y, z, yaw = static_offset(k)
            t = TransformStamped()
            t.header.stamp = self.get_clock().now().to_msg()
            t.header.frame_id = "world" if k == 0 else f"s{k - 1}"
            t.child_frame_id = f"s{k}"
            t.transform.translation.x, t.transform.translation.y = x, y
            t.transform.translation.z = z
            t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
            self.static_broadcaster.sendTransform(t)
        self.broadcaster = TransformBroadcaster(self)
        self.start = self.get_clock().now()
        self.timer = self.create_timer(0.02, self.on_timer)
        print("READY", flush=True)

    def on_timer(self) -> None:
        now = self.get_clock().now()
        t = TransformStamped()
        t.header.stamp = now.to_msg()
        t.header.frame_id = "world"
        t.child_frame_id = "moving"
        t.transform.translation.x = (now - self.start).nanoseconds / 1e9
        t.transform.rotation.w = 1.0
        self.broadcaster.sendTransform(t)


def main() -> None:
    rclpy.init()
    node = Broadcaster()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
