"""map_saver_cli: saves the map on a topic to files, as Nav2's map_saver_cli does.

``ros2 run nav2_map_server map_saver_cli -f ~/maps/office`` waits for one
message on ``/map`` (reliable, transient local: a mapping node's latched map
arrives at once), writes ``~/maps/office.pgm`` and ``~/maps/office.yaml``
(``map_io``) and exits: 0 when saved, 1 when not (no map within
``save_map_timeout`` seconds, a file that cannot be written), 255 for bad
arguments.

Arguments (before ``--ros-args``), as upstream's::

    -h/--help  -t <map_topic>  -f <mapname>  --occ <threshold_occupied>
    --free <threshold_free>  --fmt <image_format>  --mode trinary(default)/scale/raw

Parameters of its node (``map_saver``): ``save_map_timeout`` (s),
``free_thresh_default`` (0.25), ``occupied_thresh_default`` (0.65),
``map_subscribe_transient_local`` (true).

Two differences a learner will not trip over: a leading ``~`` in ``-f`` is
expanded (a shell would have; the dashboard's Console has none), and a
missing folder on the way to the file is made.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from typing import Any

import rclpy
from nav_msgs.msg import OccupancyGrid
from rclpy.executors import ExternalShutdownException
from rclpy.logging import get_logger
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.task import Future
from rclpy.utilities import remove_ros_args

from nav2_map_server.map_io import SaveParameters, save_map_to_file
from nav2_map_server.map_mode import MapMode, map_mode_from_string

USAGE = """Usage:
  map_saver_cli [arguments] [--ros-args ROS remapping args]

Arguments:
  -h/--help
  -t <map_topic>
  -f <mapname>
  --occ <threshold_occupied>
  --free <threshold_free>
  --fmt <image_format>
  --mode trinary(default)/scale/raw

NOTE: --ros-args should be passed at the end of command line"""
_NUMBER = re.compile(r"^\s*[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
EXIT_BAD_ARGUMENTS = 255  # upstream returns -1


def atof(text: str) -> float:
    """C's atof: the number a string starts with, 0.0 when it starts with none."""
    match = _NUMBER.match(text)
    return float(match.group(0)) if match else 0.0


class MapSaver(Node):
    """The saving half of Nav2's map_saver: take one map from a topic, write it to files."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("map_saver", **kwargs)
        self.get_logger().info("Creating")
        self.declare_parameter("save_map_timeout", 2.0)
        self.declare_parameter("free_thresh_default", 0.25)
        self.declare_parameter("occupied_thresh_default", 0.65)
        self.declare_parameter("map_subscribe_transient_local", True)

    def save_map_topic_to_file(self, map_topic: str, params: SaveParameters) -> bool:
        local = SaveParameters(**vars(params))
        self.get_logger().info(
            f"Saving map from '{map_topic}' topic to '{local.map_file_name}' file"
        )
        if not map_topic:
            map_topic = "map"
            self.get_logger().warning(
                f"Map topic unspecified. Map messages will be read from '{map_topic}' topic"
            )
        if local.free_thresh == 0.0:
            local.free_thresh = float(self.get_parameter("free_thresh_default").value)
            self.get_logger().warning(
                f"Free threshold unspecified. Setting it to default value: {local.free_thresh:f}"
            )
        if local.occupied_thresh == 0.0:
            local.occupied_thresh = float(self.get_parameter("occupied_thresh_default").value)
            self.get_logger().warning(
                "Occupied threshold unspecified. Setting it to default value: "
                f"{local.occupied_thresh:f}"
            )
        qos: QoSProfile | int = 10
        if self.get_parameter("map_subscribe_transient_local").value:
            qos = QoSProfile(
                depth=1,
                reliability=ReliabilityPolicy.RELIABLE,
                durability=DurabilityPolicy.TRANSIENT_LOCAL,
            )
        future: Future = Future()

        def on_map(msg: OccupancyGrid) -> None:
            if not future.done():
                future.set_result(msg)

        subscription = self.create_subscription(OccupancyGrid, map_topic, on_map, qos)
        try:
            timeout = float(self.get_parameter("save_map_timeout").value)
            rclpy.spin_until_future_complete(self, future, timeout_sec=timeout)
        finally:
            self.destroy_subscription(subscription)
        if not future.done():
            self.get_logger().error(
                f"Failed to spin map subscription: no map on '{map_topic}' within "
                f"{timeout:g} s (save_map_timeout)"
            )
            return False
        if local.map_file_name:
            target = Path(local.map_file_name).expanduser()
            local.map_file_name = str(target)
            if not target.parent.exists():
                try:
                    target.parent.mkdir(parents=True)
                except OSError as exc:
                    self.get_logger().error(f"Failed to save the map: {exc}")
                    return False
                self.get_logger().info(f"Made the folder {target.parent}")
        if save_map_to_file(future.result(), local):
            self.get_logger().info("Map saved successfully")
            return True
        self.get_logger().error("Failed to save the map")
        return False


def parse_arguments(argv: list[str]) -> tuple[str, str, SaveParameters]:
    """('valid' | 'help' | 'invalid', map_topic, save parameters) from the program's words."""
    logger = get_logger("map_saver_cli")
    params = SaveParameters()
    topic = "map"
    words = iter(argv)
    for word in words:
        if word in ("-h", "--help"):
            print(USAGE)
            return "help", topic, params
        if word == "--ros-args":
            break
        if word not in ("-t", "-f", "--occ", "--free", "--mode", "--fmt"):
            logger.error(f"Wrong argument: {word}")
            return "invalid", topic, params
        value = next(words, None)
        if value is None:
            logger.error(f"Wrong argument: {word} should be followed by a value.")
            return "invalid", topic, params
        if word == "-t":
            topic = value
        elif word == "-f":
            params.map_file_name = value
        elif word == "--occ":
            params.occupied_thresh = atof(value)
        elif word == "--free":
            params.free_thresh = atof(value)
        elif word == "--fmt":
            params.image_format = value
        else:
            try:
                params.mode = map_mode_from_string(value)
            except ValueError:
                params.mode = MapMode.TRINARY
                logger.warning(
                    f"Map mode parameter not recognized: {value}, using default value (trinary)"
                )
    return "valid", topic, params


def main(args: list[str] | None = None) -> int:
    argv = list(sys.argv if args is None else args)
    node: MapSaver | None = None
    try:
        try:
            rclpy.init(args=argv)
        except Exception as exc:  # rcl refuses the arguments
            print(f"map_saver_cli: error: {exc}", file=sys.stderr)
            return EXIT_BAD_ARGUMENTS
        status, topic, params = parse_arguments(remove_ros_args(argv)[1:])
        if status != "valid":
            return 0 if status == "help" else EXIT_BAD_ARGUMENTS
        node = MapSaver()
        return 0 if node.save_map_topic_to_file(topic, params) else 1
    except (KeyboardInterrupt, ExternalShutdownException):
        return 0
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
