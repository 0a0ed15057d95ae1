"""Benchmark: recording 10 topics at 1 kHz plus a 30 Hz camera, and replaying the bag.

A publisher process sends 10 ``std_msgs/Int64`` topics at 1 kHz (the value is
the tick number) and one 640x480 RGB ``sensor_msgs/Image`` at 30 Hz (its
``frame_id`` is the image number), and notes when it sent each. In turn, over
windows of the same length:

- **baseline**: a plain rosbags ``Writer`` fed straight from plain rclpy raw
  subscriptions (the callback writes; one process, single-threaded executor);
- **ours**: ``app.bags.Recorder`` (raw subscriptions, queue, writer thread,
  flushes every second), in a process of its own.

Both subscribe reliable with depth 1000 (what ``ros2 bag record`` picks for
reliable publishers). Figures: messages *lost* (published in the window by the
publisher's own record, missing from our bag); the recorded rate as a ratio
ours / baseline; then our bag is replayed at rate 1.0 by ``app.bags.Player``
while a plain subscriber notes arrival times on one 1 kHz topic: the replay
timing error is | arrival interval - recorded interval | per consecutive pair,
reported as p50/p95 in ms, next to how late the player itself sent each
message against its schedule (which tells the player's error from the
transport's and the subscriber's).

Run: ``.venv/bin/python tests/run.py --bench bag_record [--seconds S]``
(the issue asks for 30 s; the summary uses a shorter window). The last line
printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import threading
import time
from pathlib import Path
from typing import Any

from bench._common import (
    LOGS,
    configure_dds,
    end_bounded,
    percentile,
    ratio,
    require_private_netns,
    rounded,
    spawn,
    stop,
    wait_for_text,
)
from bench._load import load_types, publish_load

SMALL_TOPICS = tuple(f"/bench/bag_{k}" for k in range(10))
IMAGE_TOPIC = "/bench/bag_image"
TOPICS = (*SMALL_TOPICS, IMAGE_TOPIC)
WARMUP_SEC = 5.0
MARGIN_SEC = 1.0  # recording starts this long before the window and ends this long after


def _record_qos() -> Any:
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    return QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)


# ------------------------------------------------------------------ child processes


def publisher_main(out: Path) -> None:
    publish_load("bench_bag_publisher", SMALL_TOPICS, IMAGE_TOPIC, out)


def _wait_for_publishers(node: Any) -> None:
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        if all(node.count_publishers(t) for t in TOPICS):
            return
        time.sleep(0.1)
    raise SystemExit("the bench publisher's topics never appeared")


def baseline_main(bag: Path, t0: float, t1: float) -> None:
    """A plain rosbags writer, fed straight from raw subscription callbacks."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rosbags.rosbag2 import StoragePlugin, Writer

    from app.bags.definitions import definition

    Int64, Image = load_types()
    rclpy.init()
    node = Node("bench_bag_plain")
    _wait_for_publishers(node)
    writer = Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP)
    writer.open()
    time.sleep(max(0.0, t0 - MARGIN_SEC - time.monotonic()))
    for topic in TOPICS:
        msgtype = "sensor_msgs/msg/Image" if topic == IMAGE_TOPIC else "std_msgs/msg/Int64"
        msgdef, digest = definition(msgtype)
        conn = writer.add_connection(topic, msgtype, msgdef=msgdef, rihs01=digest)
        node.create_subscription(
            Image if topic == IMAGE_TOPIC else Int64,
            topic,
            lambda data, conn=conn: writer.write(conn, time.time_ns(), data),
            _record_qos(),
            raw=True,
        )
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    while time.monotonic() < t1 + MARGIN_SEC:
        executor.spin_once(timeout_sec=0.05)
    writer.close()
    end_bounded(node, executor)


def ours_main(bag: Path, t0: float, t1: float) -> None:
    """app.bags.Recorder on a RosRuntime, as `ros2 bag record` runs it."""
    from app.bags.recorder import Recorder
    from app.ros.runtime import RosRuntime

    runtime = RosRuntime("bench_bag_recorder")
    _wait_for_publishers(runtime.node)
    time.sleep(max(0.0, t0 - MARGIN_SEC - time.monotonic()))
    recorder = Recorder(runtime.node, bag, list(TOPICS))
    while len(recorder.status().topics) < len(TOPICS):
        recorder.poll()
        time.sleep(0.01)
    time.sleep(max(0.0, t1 + MARGIN_SEC - time.monotonic()))
    status = recorder.stop()
    if status.failure:
        raise SystemExit(status.failure)
    runtime.shutdown()


def listener_main(out: Path, seconds: float) -> None:
    """A plain subscriber on one 1 kHz topic: (value, arrival) for each message."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    Int64, _Image = load_types()
    rclpy.init()
    node = Node("bench_bag_listener")
    got: list[tuple[int, float]] = []
    node.create_subscription(
        Int64, SMALL_TOPICS[0], lambda m: got.append((m.data, time.monotonic())), _record_qos()
    )
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    print("LISTENER READY", flush=True)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        executor.spin_once(timeout_sec=0.05)
    out.write_text(json.dumps(got))
    end_bounded(node, executor)


def player_main(bag: Path, out: Path) -> None:
    """app.bags.Player at rate 1.0; notes how late each message left against its schedule."""
    from app.bags.player import Player, PlayOptions
    from app.ros.runtime import RosRuntime

    runtime = RosRuntime("bench_bag_player")
    player = Player(runtime.node, bag, PlayOptions(rate=1.0, topics=(SMALL_TOPICS[0],)))
    late_ms: list[float] = []
    player.run(
        threading.Event(), on_publish=lambda _s, due, sent: late_ms.append((sent - due) * 1e3)
    )
    player.close()
    runtime.shutdown()
    out.write_text(json.dumps(late_ms))


# ------------------------------------------------------------------ reading results


def _bag_values(bag: Path) -> dict[str, dict[int, int]]:
    """{topic: {tick or image number: recorded stamp ns}} from a bag."""
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    values: dict[str, dict[int, int]] = {t: {} for t in TOPICS}
    with Reader(bag) as reader:
        for conn, stamp, raw in reader.messages():
            if conn.topic == IMAGE_TOPIC:
                # Only the header: decoding 900 kB of pixels per image is not the point.
                frame = store.deserialize_cdr(raw, conn.msgtype).header.frame_id
                values[conn.topic][int(frame)] = stamp
            else:
                values[conn.topic][int.from_bytes(raw[4:12], "little", signed=True)] = stamp
    return values


def _window_ids(stamps: list[float], t0: float, t1: float) -> list[int]:
    return [k for k, t in enumerate(stamps) if t0 <= t <= t1]


def _recorded(bag: Path, pub: dict[str, list[float]], t0: float, t1: float) -> tuple[int, int]:
    """(messages of the window in the bag, messages of the window missing from it)."""
    values = _bag_values(bag)
    ticks, images = _window_ids(pub["ticks"], t0, t1), _window_ids(pub["images"], t0, t1)
    got = lost = 0
    for topic in TOPICS:
        wanted = images if topic == IMAGE_TOPIC else ticks
        have = values[topic]
        present = sum(1 for k in wanted if k in have)
        got += present
        lost += len(wanted) - present
    return got, lost


def _child(argv: list[str], log: str) -> Any:
    return spawn([sys.executable, "-m", "bench.bag_record", *argv], log)


def run(seconds: float) -> dict[str, Any]:
    require_private_netns("bag_record")
    configure_dds(60)
    LOGS.mkdir(exist_ok=True)
    work = LOGS / "bench-bags"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir()
    pub_out = work / "published.json"
    publisher, pub_log = _child(["--publisher", str(pub_out)], "bench-bag-publisher.log")
    windows: dict[str, tuple[float, float]] = {}
    try:
        wait_for_text(publisher, pub_log, "PUBLISHER READY", 30)
        for side in ("baseline", "ours"):
            t0 = time.monotonic() + WARMUP_SEC
            t1 = t0 + seconds
            windows[side] = (t0, t1)
            proc, log = _child(
                [f"--{side}", str(work / side), f"{t0!r}", f"{t1!r}"], f"bench-bag-{side}.log"
            )
            proc.wait(timeout=WARMUP_SEC + seconds + 60)
            if proc.returncode != 0:
                raise SystemExit(f"{side} failed:\n{log.read_text(errors='replace')}")
    finally:
        stop(publisher)
    pub = json.loads(pub_out.read_text())
    figures: dict[str, Any] = {"seconds": seconds}
    for side in ("baseline", "ours"):
        t0, t1 = windows[side]
        got, lost = _recorded(work / side, pub, t0, t1)
        figures[f"{side}_recorded_per_s"] = got / (t1 - t0)
        figures[f"{side}_lost"] = lost
        figures[f"{side}_published_in_window"] = got + lost
    figures["bag_lost"] = figures["ours_lost"]
    figures["bag_record_ratio"] = ratio(
        figures["ours_recorded_per_s"], figures["baseline_recorded_per_s"]
    )
    figures.update(_replay_timing(work / "ours", seconds))
    return figures


def _replay_timing(bag: Path, seconds: float) -> dict[str, Any]:
    """Play our bag's first 1 kHz topic at rate 1.0; compare arrival and recorded intervals."""
    heard = bag.parent / "replay_heard.json"
    listener, log = _child(
        ["--listener", str(heard), f"{seconds + 2 * MARGIN_SEC + 8:g}"], "bench-bag-listener.log"
    )
    wait_for_text(listener, log, "LISTENER READY", 30)
    late = bag.parent / "replay_late.json"
    player, plog = _child(["--player", str(bag), str(late)], "bench-bag-player.log")
    player.wait(timeout=seconds + 60)
    if player.returncode != 0:
        raise SystemExit(f"player failed:\n{plog.read_text(errors='replace')}")
    listener.wait(timeout=seconds + 60)
    got = [tuple(x) for x in json.loads(heard.read_text())]
    recorded = _bag_values(bag)[SMALL_TOPICS[0]]
    errors = []
    for (k0, a0), (k1, a1) in zip(got, got[1:], strict=False):
        if k0 in recorded and k1 in recorded:
            errors.append(abs((a1 - a0) - (recorded[k1] - recorded[k0]) / 1e9) * 1000)
    late_ms = json.loads(late.read_text())
    return {
        "replay_send_late_p50_ms": percentile(late_ms, 50),
        "replay_send_late_p95_ms": percentile(late_ms, 95),
        "replay_heard": len(got),
        "replay_in_bag": len(recorded),
        "replay_interval_error_p50_ms": percentile(errors, 50),
        "replay_interval_error_p95_ms": percentile(errors, 95),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench bag_record")
    parser.add_argument("--seconds", type=float, default=30.0, help="window length (issue: 30)")
    parser.add_argument("--publisher", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--baseline", nargs=3, help=argparse.SUPPRESS)
    parser.add_argument("--ours", nargs=3, help=argparse.SUPPRESS)
    parser.add_argument("--listener", nargs=2, help=argparse.SUPPRESS)
    parser.add_argument("--player", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.publisher:
        publisher_main(args.publisher)
        return 0
    if args.baseline or args.ours:
        bag, t0, t1 = args.baseline or args.ours
        (baseline_main if args.baseline else ours_main)(Path(bag), float(t0), float(t1))
        return 0
    if args.listener:
        listener_main(Path(args.listener[0]), float(args.listener[1]))
        return 0
    if args.player:
        player_main(Path(args.player[0]), Path(args.player[1]))
        return 0
    f = run(args.seconds)
    for side in ("baseline", "ours"):
        print(
            f"{side:8s}: recorded {f[f'{side}_recorded_per_s']:7.0f} msg/s, lost "
            f"{f[f'{side}_lost']} of {f[f'{side}_published_in_window']}"
        )
    print(
        f"replay: heard {f['replay_heard']} of {f['replay_in_bag']}, interval error "
        f"p50 {f['replay_interval_error_p50_ms']:.3f} ms, "
        f"p95 {f['replay_interval_error_p95_ms']:.3f} ms at the subscriber; the player sent "
        f"p50 {f['replay_send_late_p50_ms']:.3f} ms, p95 {f['replay_send_late_p95_ms']:.3f} ms "
        "after schedule"
    )
    f["aim_met"] = bool(
        f["bag_lost"] == 0
        and f["bag_record_ratio"] >= 0.95
        and f["replay_interval_error_p95_ms"] < 1.0
    )
    print(
        f"ours/plain {f['bag_record_ratio']:.3f}x (aim >= 0.95), lost {f['bag_lost']} (aim 0), "
        f"replay p95 {f['replay_interval_error_p95_ms']:.3f} ms (aim < 1 ms)"
    )
    print(json.dumps(rounded(f, 3), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
