"""view_frames: listen to /tf and /tf_static, then draw the frame tree.

As upstream: listen for ``--wait-time`` seconds (5 by default), ask the
buffer's ``tf2_frames`` service for its YAML, write ``frames_<date>.gv``
(graphviz source, upstream's text) and a picture of it. The picture is
``frames_<date>.pdf`` when graphviz's ``dot`` is installed (upstream's way),
otherwise ``frames_<date>.svg`` drawn by frames_svg.py.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import time
from typing import Any

import rclpy
import tf2_ros
import yaml
from rclpy.executors import ExternalShutdownException
from tf2_msgs.srv import FrameGraph

from tf2_tools.frames_svg import render


def generate_dot(data: dict[str, Any], recorded_time: tuple[int, int]) -> str:
    """The graphviz source upstream writes for the frames' YAML."""
    if len(data) == 0:
        return 'digraph G { "No tf data received" }'
    dot = "digraph G {\n"
    root = ""
    for el in data:
        data_map = data[el]
        dot += '"' + str(data_map["parent"]) + '" -> "' + str(el) + '"'
        dot += '[label=" '
        dot += "Broadcaster: " + str(data_map["broadcaster"]) + "\\n"
        dot += "Average rate: " + str(data_map["rate"]) + "\\n"
        dot += "Buffer length: " + str(data_map["buffer_length"]) + "\\n"
        dot += "Most recent transform: " + str(data_map["most_recent_transform"]) + "\\n"
        dot += "Oldest transform: " + str(data_map["oldest_transform"]) + "\\n"
        dot += '"];\n'
        if data_map["parent"] not in data:
            root = str(data_map["parent"])
    dot += "edge [style=invis];\n"
    dot += ' subgraph cluster_legend { style=bold; color=black; label ="view_frames Result";\n'
    dot += (
        '"Recorded at time: '
        + str(recorded_time[0] + recorded_time[1] / 1e9)
        + '"[ shape=plaintext ] ;\n'
    )
    dot += '}->"' + root + '";\n}'
    return dot


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    rclpy.init(args=argv)
    args_without_ros = rclpy.utilities.remove_ros_args(argv)
    parser = argparse.ArgumentParser(
        description="Create a diagram of the TF frames being broadcast over ROS"
    )
    parser.add_argument(
        "--wait-time",
        "-t",
        type=float,
        default=5.0,
        help="Listen to the /tf topic for this many seconds before rendering the frame tree",
    )
    parser.add_argument("-o", "--output", help="Output filename")
    parsed_args = parser.parse_args(args=args_without_ros[1:])

    node = rclpy.create_node("view_frames")
    ret = 1
    try:
        buf = tf2_ros.Buffer(node=node)
        listener = tf2_ros.TransformListener(buf, node, spin_thread=False)
        del listener  # kept alive by the node's subscriptions
        node.get_logger().info(f"Listening to tf data for {parsed_args.wait_time} seconds...")
        start_time = time.time()
        while (time.time() - start_time) < parsed_args.wait_time:
            rclpy.spin_once(node, timeout_sec=0.1)
        node.get_logger().info("Generating graph...")
        cli = node.create_client(FrameGraph, "tf2_frames")
        while not cli.wait_for_service(timeout_sec=1.0):
            node.get_logger().info("service not available, waiting again...")
        future = cli.call_async(FrameGraph.Request())
        rclpy.spin_until_future_complete(node, future)
        try:
            result = future.result()
        except Exception as e:
            node.get_logger().error(f"Service call failed {e!r}")
        else:
            ret = 0
            node.get_logger().info("Result:" + str(result))
            data = yaml.safe_load(result.frame_yaml) or {}
            if isinstance(data, list):  # "[]": no frames
                data = {}
            base = (
                parsed_args.output
                if parsed_args.output is not None
                else "frames_{:s}".format(time.strftime("%Y-%m-%d_%H.%M.%S"))
            )
            dot_program = shutil.which("dot")
            picture = f"{base}.pdf" if dot_program else f"{base}.svg"
            node.get_logger().info(f"Exporting graph in {picture} file...")
            recorded = node.get_clock().now().seconds_nanoseconds()
            with open(f"{base}.gv", "w", encoding="utf-8") as f:
                f.write(generate_dot(data, recorded))
            if dot_program:
                subprocess.run([dot_program, "-Tpdf", f"{base}.gv", "-o", picture], check=False)
            else:
                with open(picture, "w", encoding="utf-8") as f:
                    f.write(render(data, recorded[0] + recorded[1] / 1e9))
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return ret


if __name__ == "__main__":
    sys.exit(main())
