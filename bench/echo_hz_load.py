"""Benchmark: echo and hz of 11 busy topics in the dashboard, against plain subscribers.

A publisher process sends 10 topics of small messages (``std_msgs/Int64``) at
1 kHz each and one 640x480 RGB ``sensor_msgs/Image`` at 30 Hz. Then, in turn
and over the same kind of window:

- **baseline**: one plain rclpy subscriber process per topic (11 processes),
  a callback that only notes the arrival time;
- **dashboard**: the dashboard as ``serve`` builds it (viser server, ROS
  runtime, supervisor, every panel) plus, on its own node, one
  ``TopicMonitor`` per topic (the raw subscription behind the dashboard's
  echo and hz) and a 5 Hz view that deserializes each topic's latest message,
  renders it as ``ros2 topic echo`` YAML and its rate as ``ros2 topic hz``
  into a markdown handle.

Both subscribe with the dashboard's measuring QoS (best effort, depth 100).
Figures: received messages per second (dashboard / baseline), and the hz each
shows against the rate actually published in the window (the error, in %).
The reference is computed from the publisher's own record of its publish
times in the window, with the same (n - 1) / (last - first) formula.

The plain subscribers' hz is what arrived (as `ros2 topic hz` measures). The
dashboard's hz is its published rate (``TopicMonitor.published_rate``: the
publisher's clock and sequence numbers, so samples a best-effort subscription
drops do not lower it); the samples it missed are counted per topic, and the
arrival-based rate it would have shown is kept as ``dashboard_arrival_hz_*``.

Run: ``.venv/bin/python tests/run.py --bench echo_hz_load [--seconds S]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

from bench._common import (
    LOGS,
    configure_dds,
    end_bounded,
    rate_from_stamps,
    ratio,
    require_private_netns,
    rounded,
    spawn,
    stop,
    wait_for_text,
)
from bench._load import load_types, publish_load

SMALL_TOPICS = tuple(f"/bench/load_{k}" for k in range(10))
IMAGE_TOPIC = "/bench/image"
WARMUP_SEC = 6.0


def _measure_qos() -> Any:
    from app.ros.qos import MEASURE_QOS

    return MEASURE_QOS


# ------------------------------------------------------------------ child processes


def publisher_main(out: Path) -> None:
    publish_load("bench_load_publisher", SMALL_TOPICS, IMAGE_TOPIC, out)


def baseline_main(topic: str, t0: float, t1: float, out: Path) -> None:
    """One plain subscriber: note arrival times, keep those inside [t0, t1]."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    Int64, Image = load_types()
    rclpy.init()
    node = Node(f"bench_plain_{topic.rsplit('/', 1)[-1]}")
    stamps: list[float] = []
    node.create_subscription(
        Image if topic == IMAGE_TOPIC else Int64,
        topic,
        lambda _msg: stamps.append(time.monotonic()),
        _measure_qos(),
    )
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    while time.monotonic() < t1 + 0.2:
        executor.spin_once(timeout_sec=0.05)
    inside = [s for s in stamps if t0 <= s <= t1]
    out.write_text(
        json.dumps({"topic": topic, "count": len(inside), "hz": rate_from_stamps(inside)})
    )
    end_bounded(node, executor)


def dashboard_main(t0: float, t1: float, out: Path) -> None:
    """The dashboard as `serve` builds it, plus echo + hz views of every load topic."""
    from app.access import make_server
    from app.dashboard import Dashboard
    from app.exercises.editor_server import EditorHub
    from app.exercises.workspace import Workspace
    from app.lessons.progress import ProgressStore
    from app.ros.convert import to_yaml
    from app.ros.monitor import TopicMonitor
    from app.ros.runtime import RosRuntime
    from app.supervisor import Supervisor
    from app.ui import MarkdownView, code_block

    Int64, Image = load_types()
    server, _ = make_server("127.0.0.1", 0, None)  # as app/cli.py makes it
    runtime = RosRuntime()
    supervisor = Supervisor({})
    progress = ProgressStore("bench", LOGS / "bench-p")
    workspace = Workspace(progress, LOGS / "bench-scratch")
    dashboard = Dashboard(server, runtime, supervisor, progress, EditorHub(), workspace)
    dashboard.start()
    topics = [*SMALL_TOPICS, IMAGE_TOPIC]
    monitors = {
        t: TopicMonitor(
            runtime.node, t, Image if t == IMAGE_TOPIC else Int64, qos=_measure_qos(), keep=10
        )
        for t in topics
    }
    views = {t: MarkdownView(server.gui) for t in topics}
    readings: dict[str, dict[str, Any]] = {}
    stop_views = threading.Event()

    def show() -> None:  # the echo + hz views, 5 Hz as the panels refresh
        while not stop_views.wait(0.2):
            for topic, monitor in monitors.items():
                latest = monitor.message()
                stats = monitor.rate(window_sec=2.0)
                published = monitor.published_rate(window_sec=2.0)
                text = f"`ros2 topic hz {topic}`: " + (stats.ros2_text() if stats else "-")
                if published is not None:
                    text += "\n" + published.ros2_line(monitor.why_missed())
                if latest is not None:
                    text += "\n\n" + code_block(to_yaml(latest[1]).splitlines())
                views[topic].show(text)

    viewer = threading.Thread(target=show, daemon=True)
    viewer.start()
    print("DASHBOARD SIDE READY", flush=True)
    time.sleep(max(0.0, t0 - time.monotonic()))
    before = {t: m.count for t, m in monitors.items()}
    time.sleep(max(0.0, t1 - time.monotonic()))
    after = {t: m.count for t, m in monitors.items()}
    arrived = {t: m.rate(window_sec=t1 - t0) for t, m in monitors.items()}
    shown = {t: m.published_rate(window_sec=t1 - t0) for t, m in monitors.items()}
    for topic in topics:
        published, arrival = shown[topic], arrived[topic]
        readings[topic] = {
            "count": after[topic] - before[topic],
            "hz": published.rate if published else float("nan"),
            "arrival_hz": arrival.rate if arrival else float("nan"),
            "published": published.published if published else None,
            "missed": published.missed if published else None,
            "fallback": published.fallback if published else "no samples",
        }
    out.write_text(json.dumps(readings))
    stop_views.set()
    viewer.join(1.0)
    dashboard.stop()
    for monitor in monitors.values():
        monitor.close()
    runtime.shutdown()
    supervisor.shutdown()
    server.stop()


# ------------------------------------------------------------------ orchestration


def _window(seconds: float) -> tuple[float, float]:
    t0 = time.monotonic() + WARMUP_SEC
    return t0, t0 + seconds


def _published(
    pub_data: dict[str, list[float]], t0: float, t1: float
) -> tuple[dict[str, float], dict[str, int]]:
    """Each topic's published rate in [t0, t1] from the publisher's own times, and its count.

    (n - 1) / (last - first), as the subscribers measure: counting n over the
    whole window instead would be off by up to one sample (0.7 % for 30 Hz
    over 5 s) however well a subscriber measures.
    """
    ticks = [t for t in pub_data["ticks"] if t0 <= t <= t1]
    images = [t for t in pub_data["images"] if t0 <= t <= t1]
    rates = {t: rate_from_stamps(ticks) for t in SMALL_TOPICS}
    rates[IMAGE_TOPIC] = rate_from_stamps(images)
    counts = {t: len(ticks) for t in SMALL_TOPICS}
    counts[IMAGE_TOPIC] = len(images)
    return rates, counts


def _child(argv: list[str], log: str) -> tuple[subprocess.Popen, Path]:
    return spawn([sys.executable, "-m", "bench.echo_hz_load", *argv], log)


def run(seconds: float) -> dict[str, Any]:
    require_private_netns("echo_hz_load")
    configure_dds(50)
    LOGS.mkdir(exist_ok=True)
    pub_out = LOGS / "bench-load-published.json"
    publisher, pub_log = _child(["--publisher", str(pub_out)], "bench-load-publisher.log")
    results: dict[str, dict[str, Any]] = {}
    windows: dict[str, tuple[float, float]] = {}
    children: list[subprocess.Popen] = []  # ended in `finally`, whatever happens
    try:
        wait_for_text(publisher, pub_log, "PUBLISHER READY", 30)
        # Baseline: one plain subscriber process per topic.
        t0, t1 = windows["baseline"] = _window(seconds)
        procs = []
        for k, topic in enumerate([*SMALL_TOPICS, IMAGE_TOPIC]):
            out = LOGS / f"bench-load-plain-{k}.json"
            args = ["--baseline", topic, f"{t0!r}", f"{t1!r}", str(out)]
            procs.append((_child(args, f"bench-load-plain-{k}.log")[0], out))
            children.append(procs[-1][0])
        results["baseline"] = {}
        for proc, out in procs:
            try:
                proc.wait(timeout=WARMUP_SEC + seconds + 30)
            except subprocess.TimeoutExpired:
                raise SystemExit(f"a plain subscriber did not end: {proc.args!r}") from None
            if not out.exists():
                raise SystemExit(f"a plain subscriber wrote no figures (exit {proc.returncode})")
            data = json.loads(out.read_text())
            results["baseline"][data["topic"]] = data
        # Dashboard: one process, every topic.
        t0, t1 = windows["dashboard"] = _window(seconds)
        out = LOGS / "bench-load-dashboard.json"
        proc, log = _child(
            ["--dashboard-side", f"{t0!r}", f"{t1!r}", str(out)], "bench-load-dashboard.log"
        )
        children.append(proc)
        proc.wait(timeout=WARMUP_SEC + seconds + 30)
        if proc.returncode != 0:
            raise SystemExit(f"dashboard side failed:\n{log.read_text(errors='replace')}")
        results["dashboard"] = json.loads(out.read_text())
    finally:
        for child in children:
            stop(child, timeout=3.0)
        stop(publisher)
    pub_data = json.loads(pub_out.read_text())
    figures: dict[str, Any] = {"seconds": seconds}
    totals = {}
    errors: dict[str, list[float]] = {"baseline": [], "dashboard": [], "dashboard_arrival": []}
    for side in ("baseline", "dashboard"):
        t0, t1 = windows[side]
        published, sent = _published(pub_data, t0, t1)
        got = results[side]
        totals[side] = sum(got[t]["count"] for t in published) / (t1 - t0)
        for topic, rate in published.items():
            errors[side].append(_error(got[topic]["hz"], rate))
            if side == "dashboard":
                errors["dashboard_arrival"].append(_error(got[topic]["arrival_hz"], rate))
            key = "image" if topic == IMAGE_TOPIC else "small"
            figures.setdefault(f"{side}_{key}_received_hz", []).append(
                got[topic]["count"] / (t1 - t0)
            )
        figures[f"{side}_published_per_s"] = sum(published.values())
        figures[f"{side}_received_per_s"] = totals[side]
        if side == "baseline":  # plain subscribers cannot tell; counted against the record
            figures["baseline_missed_total"] = sum(
                max(0, sent[t] - got[t]["count"]) for t in published
            )
    dash = results["dashboard"]
    missed = {t: dash[t]["missed"] for t in dash}
    figures["dashboard_missed_per_topic"] = missed
    figures["dashboard_missed_total"] = sum(m for m in missed.values() if m)
    figures["dashboard_published_in_window"] = sum(dash[t]["published"] or 0 for t in dash)
    figures["dashboard_hz_fallbacks"] = {
        t: dash[t]["fallback"] for t in dash if dash[t]["fallback"]
    }
    for side in ("baseline", "dashboard"):
        for key in ("small", "image"):
            values = figures.pop(f"{side}_{key}_received_hz")
            figures[f"{side}_{key}_received_hz"] = sum(values) / len(values)
        figures[f"{side}_hz_error_percent"] = _worst(errors[side])
    figures["dashboard_arrival_hz_error_percent"] = _worst(errors["dashboard_arrival"])
    figures["echo_ratio"] = ratio(totals["dashboard"], totals["baseline"])
    figures["hz_error_percent"] = figures["dashboard_hz_error_percent"]
    return figures


def _error(hz: float, rate: float) -> float:
    """|hz - rate| / rate in %, NaN when either is unknown."""
    if not rate or math.isnan(rate) or hz is None or math.isnan(hz):
        return float("nan")
    return abs(hz - rate) / rate * 100


def _worst(errors: list[float]) -> float:
    """The largest error; NaN (a topic without a reading) counts as the worst."""
    return float("nan") if any(math.isnan(e) for e in errors) else max(errors)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench echo_hz_load")
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--publisher", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--baseline", nargs=4, help=argparse.SUPPRESS)
    parser.add_argument("--dashboard-side", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.publisher:
        publisher_main(args.publisher)
        return 0
    if args.baseline:
        topic, t0, t1, out = args.baseline
        baseline_main(topic, float(t0), float(t1), Path(out))
        return 0
    if args.dashboard_side:
        t0, t1, out = args.dashboard_side
        dashboard_main(float(t0), float(t1), Path(out))
        return 0
    f = run(args.seconds)
    for side in ("baseline", "dashboard"):
        print(
            f"{side:9s}: published {f[f'{side}_published_per_s']:7.0f} msg/s, received "
            f"{f[f'{side}_received_per_s']:7.0f} msg/s (small topics "
            f"{f[f'{side}_small_received_hz']:.0f} Hz each, image "
            f"{f[f'{side}_image_received_hz']:.1f} Hz), worst hz error "
            f"{f[f'{side}_hz_error_percent']:.1f} %"
        )
    missed = f["dashboard_missed_per_topic"]
    print(
        "dashboard missed (sequence gaps, best effort): "
        + ", ".join(f"{t.rsplit('/', 1)[-1]} {m}" for t, m in missed.items())
        + f"; total {f['dashboard_missed_total']} of {f['dashboard_published_in_window']}"
        + f" (plain subscribers: {f['baseline_missed_total']} not received)"
    )
    if f["dashboard_hz_fallbacks"]:
        print(f"dashboard hz from arrival times for: {f['dashboard_hz_fallbacks']}")
    print(
        f"dashboard hz from arrival times alone (as ros2 topic hz): worst error "
        f"{f['dashboard_arrival_hz_error_percent']:.2f} %"
    )
    f["aim_met"] = bool(f["echo_ratio"] >= 0.9 and f["hz_error_percent"] <= 1.0)
    print(
        f"received ratio dashboard/plain {f['echo_ratio']:.2f}x (aim >= 0.9), dashboard hz "
        f"error {f['hz_error_percent']:.2f} % (aim <= 1 %)"
    )
    print(json.dumps(rounded(f, 2), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
