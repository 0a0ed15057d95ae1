"""Step action ``publish``: publish a message on a topic, `times` of them at `rate_hz` (e.g.
a drive without a keyboard).
"""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING

from rclpy.exceptions import InvalidHandle
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy

from app.lessons.registry import register_action
from app.ros.convert import fill, import_type

RCLError = _rclpy.RCLError

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_action(
    "publish",
    required="topic type message",
    optional="label times rate_hz",
    words="publish a message on a topic, `times` of them at `rate_hz` "
    "(e.g. a drive without a keyboard)",
)
def perform(rt: LessonRuntime, action: Spec) -> str:
    msg_type = import_type(action["type"])
    message = fill(msg_type, action["message"])
    times, period = int(action.get("times", 1)), 1.0 / float(action.get("rate_hz", 1.0))
    with rt.lock:
        key = (action["topic"], action["type"])
        if key not in rt.senders:
            rt.senders[key] = rt.node.create_publisher(msg_type, action["topic"], 10)
        publisher = rt.senders[key]

    def send() -> None:  # off the UI thread: the burst takes times / rate_hz seconds
        for index in range(times):
            if index:
                time.sleep(period)
            try:
                publisher.publish(message)
            except (InvalidHandle, RCLError):  # the dashboard is closing: the burst ends here
                return

    threading.Thread(target=send, name=f"lesson-publish-{key[0]}", daemon=True).start()
    return f"Publishing {times} message(s) on {action['topic']}."
