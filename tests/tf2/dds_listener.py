"""A late-joining listener process for test_tf2_outside.py; prints what it learned as JSON.

``given``: TransformListener on this program's node with ``spin_thread=True``;
``own``: TransformListener(buffer) alone, which makes and spins its own node.
Imports only tf2_ros and rclpy.
"""

from __future__ import annotations

import json
import sys
import time

import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.time import Time
from tf2_ros import Buffer, TransformException, TransformListener


def main() -> None:
    mode = sys.argv[1]
    rclpy.init()
    node = Node(f"outside_listener_{mode}")
    buffer = Buffer()
    if mode == "given":
        listener = TransformListener(buffer, node, spin_thread=True)
    else:
        listener = TransformListener(buffer)
    out: dict[str, object] = {"mode": mode}
    try:
        start = time.monotonic()
        last = buffer.lookup_transform("world", "s11", Time(), timeout=Duration(seconds=20.0))
        out["static_wait_s"] = time.monotonic() - start
        tr, r = last.transform.translation, last.transform.rotation
        out["s11"] = [tr.x, tr.y, tr.z, r.x, r.y, r.z, r.w]
        out["s11_stamp"] = [last.header.stamp.sec, last.header.stamp.nanosec]
        # Three readings of the newest pose, each at least 0.3 s after the one before by
        # the frame's own stamps, not by this program's sleeps: on a loaded machine the
        # listener's thread can fall behind the wall clock, and the buffer then held less
        # than the 0.51 s the lookup in the past below needs.
        xs: list[float] = []
        newest = None
        deadline = time.monotonic() + 30.0
        while len(xs) < 3:
            moving = buffer.lookup_transform(
                "world", "moving", Time(), timeout=Duration(seconds=10.0)
            )
            stamp = Time.from_msg(moving.header.stamp)
            if newest is None or stamp - newest >= Duration(seconds=0.3):
                xs.append(moving.transform.translation.x)
                newest = stamp
            elif time.monotonic() > deadline:
                raise TransformException(f"'moving' stopped at {stamp.nanoseconds} ns")
            else:
                time.sleep(0.05)
        out["moving_x"] = xs
        # the frame a little in the past, between two stamps: interpolated
        stamp = Time.from_msg(moving.header.stamp) - Duration(seconds=0.51)
        past = buffer.lookup_transform("world", "moving", stamp)
        out["moving_past_x"] = past.transform.translation.x
        out["frames"] = sorted(buffer._getFrameStrings())
    except TransformException as exc:
        out["error"] = f"{type(exc).__name__}: {exc}"
    print(json.dumps(out), flush=True)
    rclpy.try_shutdown()  # stops the listener's executor; then its thread ends
    listener.dedicated_listener_thread.join(timeout=10.0)
    node.destroy_node()


if __name__ == "__main__":
    main()
