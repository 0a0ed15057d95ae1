"""The busy load two benchmarks share: 10 small topics at 1 kHz and a camera at 30 Hz.

A child process publishes ``std_msgs/Int64`` on each small topic (the value is
the tick number) and a 640x480 RGB ``sensor_msgs/Image`` (its ``frame_id`` is
the image number), and writes when it sent each, so a benchmark can count
what was published in its window from the publisher's own record.
"""

from __future__ import annotations

import json
import signal
import threading
import time
from collections.abc import Sequence
from pathlib import Path

SMALL_HZ = 1000.0
IMAGE_HZ = 30.0


def load_types() -> tuple[type, type]:
    from sensor_msgs.msg import Image
    from std_msgs.msg import Int64

    return Int64, Image


def publish_load(node_name: str, small_topics: Sequence[str], image_topic: str, out: Path) -> None:
    """Publish until SIGINT; then write the monotonic time of every tick and image to ``out``."""
    import rclpy
    from rclpy.node import Node

    Int64, Image = load_types()
    rclpy.init()
    node = Node(node_name)
    small = [node.create_publisher(Int64, t, 10) for t in small_topics]
    image_pub = node.create_publisher(Image, image_topic, 10)
    image = Image(height=480, width=640, encoding="rgb8", step=640 * 3)
    image.data = bytes(640 * 480 * 3)
    msg = Int64()
    ticks: list[float] = []
    images: list[float] = []
    stopping = threading.Event()
    signal.signal(signal.SIGINT, lambda *_: stopping.set())
    print("PUBLISHER READY", flush=True)
    start = time.monotonic()
    k = 0
    next_image = start
    while not stopping.is_set():
        due = start + k / SMALL_HZ
        now = time.monotonic()
        if due > now:
            time.sleep(due - now)
        msg.data = k
        for pub in small:
            pub.publish(msg)
        ticks.append(time.monotonic())
        k += 1
        if ticks[-1] >= next_image:
            image.header.frame_id = str(len(images))
            image_pub.publish(image)
            images.append(time.monotonic())
            next_image += 1.0 / IMAGE_HZ
    out.write_text(json.dumps({"ticks": ticks, "images": images}))
    node.destroy_node()
    rclpy.try_shutdown()
