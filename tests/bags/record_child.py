"""A process that records a busy topic it publishes itself, for the fault tests.

``python -m tests.bags.record_child BAG SECONDS [COPY_TO|-] [STORAGE]``: publishes
/bulk (std_msgs/String, 20 kB each, 100 Hz) from a second participant and
records it with app.bags.Recorder (flushing every 0.2 s). Prints a status
line every 0.1 s ("flushed N count M") so the test can kill it at a known
point; a recording that fails prints "FAILED: <message>", and with COPY_TO
the bag folder is copied there (the disk it was on may vanish with us).
"""

from __future__ import annotations

import shutil
import sys
import threading
import time
from pathlib import Path

from rclpy.qos import QoSProfile
from std_msgs.msg import String

from app.bags.recorder import Recorder
from app.ros.runtime import RosRuntime

PAYLOAD = "x" * 20_000


def feed(runtime: RosRuntime, stop: threading.Event) -> None:
    pub = runtime.node.create_publisher(String, "/bulk", QoSProfile(depth=100))
    n = 0
    while not stop.wait(0.01):
        n += 1
        pub.publish(String(data=f"{n} {PAYLOAD}"))


def main(argv: list[str]) -> int:
    bag, seconds = Path(argv[0]), float(argv[1])
    copy_to = Path(argv[2]) if len(argv) > 2 and argv[2] != "-" else None
    storage = argv[3] if len(argv) > 3 else "mcap"
    feeder, recorder_rt = RosRuntime("bulk_feeder"), RosRuntime("bulk_recorder")
    stop = threading.Event()
    thread = threading.Thread(target=feed, args=(feeder, stop), daemon=True)
    thread.start()
    recorder = Recorder(recorder_rt.node, bag, ["/bulk"], storage=storage, flush_interval=0.2)
    code = 0
    try:
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            recorder.poll()
            status = recorder.status()
            print(f"flushed {status.flushed} count {status.count}", flush=True)
            if status.failure:
                break
            time.sleep(0.1)
    finally:
        status = recorder.stop()
        stop.set()
        thread.join(2)
    if status.failure:
        print(f"FAILED: {status.failure}", flush=True)
        code = 3
    if copy_to is not None:
        shutil.copytree(bag, copy_to)
    print(f"done flushed {status.flushed} count {status.count}", flush=True)
    feeder.shutdown()
    recorder_rt.shutdown()
    return code


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
