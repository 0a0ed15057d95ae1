"""The simulated world draws its camera's picture only while something subscribes to it.

Software rendering at 15 Hz is most of an idle world's CPU, and a class's server runs
one world per learner on the navigation lessons while few of them look at the camera.
Gazebo's cameras skip rendering without a subscriber; so does ours. What a subscriber
gets is unchanged: pictures at the camera's rate from its first moments.
"""

from __future__ import annotations

import threading
import time

import psutil
import pytest
from sensor_msgs.msg import CameraInfo, Image

from tests.conftest import wait_until

pytestmark = pytest.mark.ros

WINDOW_SEC = 6.0


def _cpu_seconds(pid: int, seconds: float) -> float:
    process = psutil.Process(pid)
    before = process.cpu_times()
    time.sleep(seconds)
    after = process.cpu_times()
    return (after.user - before.user) + (after.system - before.system)


def test_pictures_are_drawn_for_a_subscriber_and_not_without_one(supervisor, probe):
    status = supervisor.start("sim_world")  # the camera on, at its 15 Hz
    wait_until(
        lambda: (
            ("/camera/image_raw", ["sensor_msgs/msg/Image"])
            in probe.node.get_topic_names_and_types()
        ),
        timeout=60,
        what="the world's camera topic",
    )
    infos: list[float] = []
    info_sub = probe.node.create_subscription(
        CameraInfo, "/camera/camera_info", lambda _m: infos.append(time.monotonic()), 5
    )
    wait_until(lambda: len(infos) >= 5, timeout=30, what="camera_info without a picture reader")
    unread = _cpu_seconds(status.pid, WINDOW_SEC)

    frames: list[Image] = []
    lock = threading.Lock()

    def keep(message: Image) -> None:
        with lock:
            frames.append(message)

    image_sub = probe.node.create_subscription(Image, "/camera/image_raw", keep, 5)
    try:
        wait_until(lambda: len(frames) >= 3, timeout=30, what="pictures for a subscriber")
        with lock:
            start = len(frames)
        read = _cpu_seconds(status.pid, WINDOW_SEC)
        with lock:
            got, last = len(frames) - start, frames[-1]
    finally:
        probe.node.destroy_subscription(image_sub)
        probe.node.destroy_subscription(info_sub)
    assert (last.width, last.height, last.encoding) == (320, 240, "rgb8")
    assert any(last.data), "a black picture"
    # 15 Hz while read; at least half of that on a machine the suite keeps busy.
    assert got >= 0.5 * 15 * WINDOW_SEC, got
    # The drawing was the difference: without a reader the world did far less work.
    assert unread < 0.7 * read, (unread, read)
