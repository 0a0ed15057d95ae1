"""tf2_echo SOURCE TARGET [RATE]: print a transform once a second, as upstream does.

The transform printed maps data in TARGET into SOURCE (upstream's usage text
says so); the format is upstream's, to the digit: ``At time S.N`` (nanoseconds
unpadded, as upstream prints them), translation, quaternion, RPY in radians
and degrees, and the 4x4 matrix.
"""

from __future__ import annotations

import math
import sys

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.time import Time
from tf2_py.linear_math import euler_from_matrix, matrix_from_quaternion

from tf2_ros import TransformException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener

USAGE = (
    "Usage: tf2_echo source_frame target_frame [echo_rate]\n\n"
    "This will echo the transform from the coordinate frame of the source_frame\n"
    "to the coordinate frame of the target_frame. \n"
    "Note: This is the transform to get data from target_frame into the source_frame.\n"
    "Default echo rate is 1 if echo_rate is not given.\n"
)


def format_transform(transform: TransformStamped) -> str:
    """The block tf2_echo prints for one transform."""
    stamp = transform.header.stamp
    t = transform.transform.translation
    r = transform.transform.rotation
    m = matrix_from_quaternion((r.x, r.y, r.z, r.w))
    roll, pitch, yaw = euler_from_matrix(m)
    deg = 180.0 / math.pi
    xyz = (t.x, t.y, t.z)
    lines = [
        f"At time {stamp.sec}.{stamp.nanosec}",
        f"- Translation: [{t.x:.3f}, {t.y:.3f}, {t.z:.3f}]",
        f"- Rotation: in Quaternion [{r.x:.3f}, {r.y:.3f}, {r.z:.3f}, {r.w:.3f}]",
        f"- Rotation: in RPY (radian) [{roll:.3f}, {pitch:.3f}, {yaw:.3f}]",
        f"- Rotation: in RPY (degree) [{roll * deg:.3f}, {pitch * deg:.3f}, {yaw * deg:.3f}]",
        "- Matrix:",
    ]
    for i in range(3):
        lines.append("".join(f" {m[i][j]:6.3f}" for j in range(3)) + f" {xyz[i]:6.3f}")
    lines.append("".join(f" {0.0:6.3f}" for _ in range(3)) + f" {1.0:6.3f}")
    return "\n".join(lines)


class Tf2Echo(Node):
    """Waits for the transform, then prints it at ``rate`` Hz."""

    def __init__(self, source_frame: str, target_frame: str, rate_hz: float) -> None:
        super().__init__("tf2_echo")
        self.source_frame = source_frame
        self.target_frame = target_frame
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.ready = False
        self.timer = self.create_timer(1.0 / rate_hz, self.on_timer)

    def on_timer(self) -> None:
        if not self.ready:
            self.ready, why = self.tf_buffer.can_transform_core(
                self.source_frame, self.target_frame, Time()
            )
            if not self.ready:
                self.get_logger().info(
                    f"Waiting for transform {self.source_frame} ->  {self.target_frame}: {why}",
                    throttle_duration_sec=1.0,
                )
                return
        try:
            transform = self.tf_buffer.lookup_transform(
                self.source_frame, self.target_frame, Time()
            )
        except TransformException as ex:
            now = self.get_clock().now().nanoseconds / 1e9
            print(f"Failure at {now:.3f}", flush=True)
            print(f"Exception thrown:{ex}", flush=True)
            print("The current list of frames is:", flush=True)
            print(self.tf_buffer.all_frames_as_string(), flush=True)
            return
        print(format_transform(transform), flush=True)


def parse_rate(args: list[str]) -> tuple[float | None, int]:
    """(rate, exit code): upstream's argument rules for ``source target [rate]``."""
    if len(args) == 3:
        return 1.0, 0
    if len(args) == 4:
        try:
            rate = float(args[3])
        except ValueError:
            print(
                f"Failed to convert rate argument '{args[3]}' to a floating-point number",
                file=sys.stderr,
            )
            return None, 2
        if not rate > 0.0 or math.isinf(rate):
            print(f"tf2_echo: the rate must be a positive number, got '{args[3]}'", file=sys.stderr)
            return None, 2
        return rate, 0
    print(USAGE, end="", flush=True)
    return None, 1


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    args = rclpy.utilities.remove_ros_args(argv)
    rate, code = parse_rate(args)
    if rate is None:
        return code
    node: Tf2Echo | None = None
    try:
        rclpy.init(args=argv)
        node = Tf2Echo(args[1], args[2], rate)
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
