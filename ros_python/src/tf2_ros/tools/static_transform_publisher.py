"""static_transform_publisher: publish one static transform from the command line.

Upstream's two forms: flags (``--x --y --z``, ``--qx --qy --qz --qw`` or
``--roll --pitch --yaw``, ``--frame-id --child-frame-id``) and the deprecated
positional ``x y z yaw pitch roll frame child`` / ``x y z qx qy qz qw frame
child``, with upstream's warnings, errors and usage text. The node's name is
``static_transform_publisher_`` plus 16 random characters, as upstream's.
"""

from __future__ import annotations

import math
import random
import string
import sys
from dataclasses import dataclass, field

import rclpy
from geometry_msgs.msg import TransformStamped
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter
from tf2_py.linear_math import quaternion_from_euler

from tf2_ros.static_transform_broadcaster import StaticTransformBroadcaster
from tf2_ros.tools._logging import rcutils_log

USAGE = (
    "usage: static_transform_publisher [--x X] [--y Y] [--z Z] [--qx QX] [--qy QY] "
    "[--qz QZ] [--qw QW] [--roll ROLL] [--pitch PITCH] [--yaw YAW] --frame-id FRAME_ID "
    "--child-frame-id CHILD_FRAME_ID\n\n"
    "A command line utility for manually sending a static transform.\n\nIf no translation or"
    " orientation is provided, the identity transform will be published.\n\nThe translation offsets"
    " are in meters.\n\nThe rotation may be provided with roll, pitch, yaw euler angles in radians,"
    " or as a quaternion.\n\n"
    "required arguments:\n"
    "  --frame-id FRAME_ID parent frame\n"
    "  --child-frame-id CHILD_FRAME_ID child frame id\n\n"
    "optional arguments:\n"
    "  --x X                 x component of translation\n"
    "  --y Y                 y component of translation\n"
    "  --z Z                 z component of translation\n"
    "  --qx QX               x component of quaternion rotation\n"
    "  --qy QY               y component of quaternion rotation\n"
    "  --qz QZ               z component of quaternion rotation\n"
    "  --qw QW               w component of quaternion rotation\n"
    "  --roll ROLL           roll component Euler rotation\n"
    "  --pitch PITCH         pitch component Euler rotation\n"
    "  --yaw YAW             yaw component Euler rotation"
)

_TRANS = {"--x": 0, "--y": 1, "--z": 2}
_QUAT = {"--qx": 0, "--qy": 1, "--qz": 2, "--qw": 3}
_RPY = {"--roll": 0, "--pitch": 1, "--yaw": 2}


@dataclass
class StaticTransform:
    translation: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rotation: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0, 1.0])
    frame_id: str = ""
    child_frame_id: str = ""
    help: bool = False


class ArgumentError(ValueError):
    """Upstream's parse error text."""


def _number(optname: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ArgumentError(f"Failed to parse {optname} argument as float") from None
    if math.isnan(value) and text.strip().lower() != "nan":
        raise ArgumentError(f"Failed to parse {optname} argument as float")
    return value


def parse_args(args: list[str]) -> StaticTransform:
    """Upstream's rules (args[0] is the program name); raises ArgumentError."""
    if len(args) < 1:
        raise ArgumentError("Not enough arguments to parse")
    out = StaticTransform()
    rpy = [0.0, 0.0, 0.0]
    saw_frame = saw_quat = saw_rpy = saw_trans = False
    positional: list[str] = []
    i = 1
    while i < len(args):
        name = args[i]
        if name in ("--help", "-h"):
            out.help = True
        elif (
            name in _TRANS
            or name in _QUAT
            or name in _RPY
            or name
            in (
                "--frame-id",
                "--child-frame-id",
            )
        ):
            if i == len(args) - 1:
                raise ArgumentError(f"Not enough arguments for {name}")
            i += 1
            value = args[i]
            if name in _TRANS:
                out.translation[_TRANS[name]] = _number(name, value)
                saw_trans = True
            elif name in _QUAT:
                out.rotation[_QUAT[name]] = _number(name, value)
                saw_quat = True
            elif name in _RPY:
                rpy[_RPY[name]] = _number(name, value)
                saw_rpy = True
            elif name == "--frame-id":
                out.frame_id = value
                saw_frame = True
            else:
                out.child_frame_id = value
                saw_frame = True
        else:
            positional.append(name)
        i += 1
    if out.help:
        return out
    if saw_rpy and saw_quat:
        raise ArgumentError("Cannot specify both quaternion and Euler rotations")
    if saw_rpy:
        out.rotation = list(quaternion_from_euler(*rpy))
    if len(positional) in (8, 9):
        rcutils_log(
            "WARN", "Old-style arguments are deprecated; see --help for new-style arguments"
        )
        if saw_frame or saw_trans or saw_quat:
            raise ArgumentError("Cannot specify both new-style (flags) and old-style (arguments)")
        out.translation = [
            _number(n, v) for n, v in zip(("x", "y", "z"), positional[:3], strict=False)
        ]
        if len(positional) == 8:
            yaw, pitch, roll = (
                _number(n, v)
                for n, v in zip(("yaw", "pitch", "roll"), positional[3:6], strict=False)
            )
            out.rotation = list(quaternion_from_euler(roll, pitch, yaw))
            out.frame_id, out.child_frame_id = positional[6], positional[7]
        else:
            out.rotation = [
                _number(n, v)
                for n, v in zip(("qx", "qy", "qz", "qw"), positional[3:7], strict=False)
            ]
            out.frame_id, out.child_frame_id = positional[7], positional[8]
    elif positional:
        raise ArgumentError("Extra unparsed arguments on command-line")
    if out.frame_id == "":
        raise ArgumentError("Frame id must not be empty")
    if out.child_frame_id == "":
        raise ArgumentError("Child frame id must not be empty")
    return out


def unique_node_name() -> str:
    chars = string.digits + string.ascii_letters
    return "static_transform_publisher_" + "".join(random.choice(chars) for _ in range(16))


class StaticTransformBroadcasterNode(Node):
    """Declares the transform as read-only parameters and sends it once on /tf_static."""

    def __init__(self, parsed: StaticTransform) -> None:
        overrides = [
            Parameter("translation.x", value=parsed.translation[0]),
            Parameter("translation.y", value=parsed.translation[1]),
            Parameter("translation.z", value=parsed.translation[2]),
            Parameter("rotation.x", value=parsed.rotation[0]),
            Parameter("rotation.y", value=parsed.rotation[1]),
            Parameter("rotation.z", value=parsed.rotation[2]),
            Parameter("rotation.w", value=parsed.rotation[3]),
            Parameter("frame_id", value=parsed.frame_id),
            Parameter("child_frame_id", value=parsed.child_frame_id),
        ]
        super().__init__(unique_node_name(), parameter_overrides=overrides)
        read_only = ParameterDescriptor(read_only=True)
        msg = TransformStamped()
        msg.header.stamp = self.get_clock().now().to_msg()
        t, r = msg.transform.translation, msg.transform.rotation
        t.x = self.declare_parameter("translation.x", 0.0, read_only).value
        t.y = self.declare_parameter("translation.y", 0.0, read_only).value
        t.z = self.declare_parameter("translation.z", 0.0, read_only).value
        r.x = self.declare_parameter("rotation.x", 0.0, read_only).value
        r.y = self.declare_parameter("rotation.y", 0.0, read_only).value
        r.z = self.declare_parameter("rotation.z", 0.0, read_only).value
        r.w = self.declare_parameter("rotation.w", 1.0, read_only).value
        msg.header.frame_id = self.declare_parameter("frame_id", "/frame", read_only).value
        msg.child_frame_id = self.declare_parameter("child_frame_id", "/child", read_only).value
        if msg.header.frame_id == msg.child_frame_id:
            self.get_logger().error(
                f"cannot publish static transform from '{msg.header.frame_id}' to "
                f"'{msg.child_frame_id}', exiting"
            )
            raise ValueError("child_frame_id cannot equal frame_id")
        self.broadcaster = StaticTransformBroadcaster(self)
        self.broadcaster.sendTransform(msg)


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    args = rclpy.utilities.remove_ros_args(argv)
    try:
        parsed = parse_args(args)
    except ArgumentError as exc:
        rcutils_log("ERROR", f"error parsing command line arguments: {exc}")
        print(USAGE, flush=True)
        return 1
    if parsed.help:
        print(USAGE, flush=True)
        return 0
    node: StaticTransformBroadcasterNode | None = None
    try:
        rclpy.init(args=argv)
        try:
            node = StaticTransformBroadcasterNode(parsed)
        except ValueError:
            return 1
        t, r = parsed.translation, parsed.rotation
        node.get_logger().info(
            "Spinning until stopped - publishing transform\n"
            f"translation: ('{t[0]:f}', '{t[1]:f}', '{t[2]:f}')\n"
            f"rotation: ('{r[0]:f}', '{r[1]:f}', '{r[2]:f}', '{r[3]:f}')\n"
            f"from '{parsed.frame_id}' to '{parsed.child_frame_id}'"
        )
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
