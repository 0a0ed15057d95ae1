"""``ros2-classroom foxglove``: the live ROS graph for Foxglove, until Ctrl+C.

Its own ROS participant (``/classroom_foxglove``), so it runs beside a
dashboard or alone, on the same ROS domain. DDS stays on loopback and the
WebSocket on 127.0.0.1 unless the caller chose otherwise (app/cli.py).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from app.foxglove.bridge import FoxgloveBridge

NODE_NAME = "classroom_foxglove"


def serve(host: str, port: int, stop: threading.Event, say: Callable[[str], None]) -> int:
    """Run the bridge until ``stop`` is set; RuntimeError if the port cannot be had."""
    from app.ros.runtime import RosRuntime

    runtime = RosRuntime(NODE_NAME)
    bridge = FoxgloveBridge(runtime.node, host=host, port=port)
    try:
        bridge.start()
    except Exception:
        runtime.shutdown()
        raise
    say(
        f"Foxglove bridge is ready: {bridge.url}  (in Foxglove or Lichtblick: Open connection "
        "→ Foxglove WebSocket → this URL). Press Ctrl+C to stop."
    )
    stop.wait()
    say("Shutting down…")
    started = time.monotonic()
    bridge.close()
    runtime.shutdown()
    say(f"Stopped in {time.monotonic() - started:.1f} s.")
    return 0
