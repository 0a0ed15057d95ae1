"""Benchmark: tf2 lookups on a full cache, and the CPU cost of ingesting /tf over DDS.

1. ``lookup_transform`` latency (p50/p99) on a 20-frame tree whose dynamic
   frames each hold a full 10 s cache at 100 Hz (1000 stamps per frame),
   between random frame pairs at random times (interpolated) and at time zero;
   beside the same lookups done in plain numpy (per-frame stamp arrays,
   ``searchsorted``, lerp + slerp, 4x4 matrices up to the root), in this run.
2. Ingest: a publisher process sends 2,000 transforms/s on /tf (20 frames per
   message at 100 Hz); a tf2 process (Buffer + TransformListener) and a plain
   rclpy subscriber that stores the same transforms into numpy arrays listen
   at the same time; each reports its own CPU time (all threads) over the
   window, in % of one core, and how many transforms it received.

Run: ``.venv/bin/python tests/run.py --bench tf2_lookup [--seconds S] [--lookups N]``.
The last line printed is one JSON object (``tf2_lookup_p50_us``,
``tf2_ingest_cpu_percent``, ...).
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from typing import Any

import numpy as np

from bench._common import configure_dds, percentile, require_private_netns, rounded

FRAMES = 20
RATE_HZ = 100
CACHE_S = 10
INGEST_PER_S = 2000
AIM_LOOKUP_US = 50.0
AIM_INGEST_PERCENT = 10.0


# -- the tree -----------------------------------------------------------------------
def make_tree(rng: np.random.Generator) -> tuple[list[int], list[bool]]:
    """Parents (frame 0 is the root) and which frames are static (a quarter)."""
    parents = [-1] + [int(rng.integers(0, i)) for i in range(1, FRAMES)]
    static = [False] + [bool(rng.random() < 0.25) for _ in range(1, FRAMES)]
    return parents, static


def samples(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """n translations and n unit quaternions (x, y, z, w) drifting smoothly."""
    t = np.cumsum(rng.normal(0, 0.01, (n, 3)), axis=0)
    angles = np.cumsum(rng.normal(0, 0.01, n))
    q = np.zeros((n, 4))
    q[:, 2], q[:, 3] = np.sin(angles / 2), np.cos(angles / 2)
    return t, q


def quat_matrix(q: np.ndarray) -> np.ndarray:
    x, y, z, w = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


class NumpyTree:
    """The baseline: the same data and lookups, written plainly with numpy."""

    def __init__(self, parents: list[int], stamps: np.ndarray, data: dict[int, Any]) -> None:
        self.parents = parents
        self.stamps = stamps
        self.data = data  # frame -> (translations (n,3), quats (n,4)) or a static (t, q)

    def local(self, frame: int, t_ns: int) -> np.ndarray:
        tr, q = self.data[frame]
        m = np.eye(4)
        if tr.ndim == 1:
            m[:3, :3], m[:3, 3] = quat_matrix(q), tr
            return m
        i = int(np.searchsorted(self.stamps, t_ns, side="right")) - 1
        i = min(max(i, 0), len(self.stamps) - 2)
        r = (t_ns - self.stamps[i]) / (self.stamps[i + 1] - self.stamps[i])
        q0, q1 = q[i], q[i + 1]
        d = float(np.dot(q0, q1))
        if d < 0:
            q1, d = -q1, -d
        if d > 0.9999995:
            qi = q0 + (q1 - q0) * r
        else:
            th = math.acos(d)
            qi = (math.sin((1 - r) * th) * q0 + math.sin(r * th) * q1) / math.sin(th)
        m[:3, :3] = quat_matrix(qi / np.linalg.norm(qi))
        m[:3, 3] = tr[i] + (tr[i + 1] - tr[i]) * r
        return m

    def to_root(self, frame: int, t_ns: int) -> np.ndarray:
        m = np.eye(4)
        while frame != 0:
            m = self.local(frame, t_ns) @ m
            frame = self.parents[frame]
        return m

    def lookup(self, target: int, source: int, t_ns: int) -> np.ndarray:
        return np.linalg.inv(self.to_root(target, t_ns)) @ self.to_root(source, t_ns)


def lookup_latency(n_lookups: int) -> dict[str, float]:
    """p50/p99 of Buffer.lookup_transform and of the numpy baseline, same queries."""
    from geometry_msgs.msg import TransformStamped
    from rclpy.time import Time
    from tf2_ros import Buffer

    rng = np.random.default_rng(7)
    parents, static = make_tree(rng)
    n = RATE_HZ * CACHE_S
    t0 = 1_000 * 1_000_000_000
    stamps = t0 + np.arange(n, dtype=np.int64) * (1_000_000_000 // RATE_HZ)
    buf = Buffer()
    data: dict[int, Any] = {}
    for frame in range(1, FRAMES):
        tr, q = samples(rng, n)
        msg = TransformStamped()
        msg.header.frame_id, msg.child_frame_id = f"f{parents[frame]}", f"f{frame}"
        if static[frame]:
            data[frame] = (tr[0], q[0])
            msg.transform.translation.x, msg.transform.translation.y = tr[0][:2]
            msg.transform.translation.z = tr[0][2]
            msg.transform.rotation.z, msg.transform.rotation.w = q[0][2:]
            buf.set_transform_static(msg, "bench")
            continue
        data[frame] = (tr, q)
        for k in range(n):
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(stamps[k]), 1_000_000_000)
            msg.transform.translation.x, msg.transform.translation.y = tr[k][:2]
            msg.transform.translation.z = tr[k][2]
            msg.transform.rotation.z, msg.transform.rotation.w = q[k][2:]
            buf.set_transform(msg, "bench")
    plain = NumpyTree(parents, stamps, data)
    queries = []
    for i in range(n_lookups):
        a, b = (int(v) for v in rng.choice(FRAMES, 2, replace=False))
        t_ns = 0 if i % 10 == 0 else int(rng.integers(stamps[0], stamps[-1]))
        queries.append((a, b, t_ns))
    times = [Time(nanoseconds=t) for _a, _b, t in queries]
    tf2_us, np_us = [], []
    worst = 0.0
    for (a, b, t_ns), stamp in zip(queries, times, strict=True):
        start = time.perf_counter_ns()
        got = buf.lookup_transform(f"f{a}", f"f{b}", stamp)
        tf2_us.append((time.perf_counter_ns() - start) / 1000)
        used = got.header.stamp.sec * 1_000_000_000 + got.header.stamp.nanosec
        start = time.perf_counter_ns()
        want = plain.lookup(a, b, used if t_ns == 0 else t_ns)
        np_us.append((time.perf_counter_ns() - start) / 1000)
        tr = got.transform.translation
        worst = max(worst, float(np.max(np.abs(want[:3, 3] - [tr.x, tr.y, tr.z]))))
    if worst > 1e-6:
        raise RuntimeError(f"tf2 and the numpy baseline disagree by {worst} m")
    return {
        "tf2_lookup_p50_us": percentile(tf2_us, 50),
        "tf2_lookup_p99_us": percentile(tf2_us, 99),
        "numpy_lookup_p50_us": percentile(np_us, 50),
        "numpy_lookup_p99_us": percentile(np_us, 99),
        "lookup_ratio": percentile(tf2_us, 50) / percentile(np_us, 50),
        "lookups": len(tf2_us),
        "max_difference_m": worst,
    }


# -- ingest over DDS ---------------------------------------------------------------------
def role_publisher(seconds: float) -> None:
    import rclpy
    from geometry_msgs.msg import TransformStamped
    from tf2_msgs.msg import TFMessage

    rclpy.init()
    node = rclpy.create_node("bench_tf_publisher")
    pub = node.create_publisher(TFMessage, "/tf", 100)
    per_msg = INGEST_PER_S // RATE_HZ
    msg = TFMessage()
    for k in range(per_msg):
        t = TransformStamped()
        t.header.frame_id = "world" if k == 0 else f"g{k - 1}"
        t.child_frame_id = f"g{k}"
        t.transform.rotation.w = 1.0
        msg.transforms.append(t)
    end = time.monotonic() + seconds
    next_at = time.monotonic()
    while time.monotonic() < end:
        stamp = node.get_clock().now().to_msg()
        for k, t in enumerate(msg.transforms):
            t.header.stamp = stamp
            t.transform.translation.x = math.sin(time.monotonic() + k)
        pub.publish(msg)
        next_at += 1.0 / RATE_HZ
        time.sleep(max(0.0, next_at - time.monotonic()))
    node.destroy_node()
    rclpy.try_shutdown()


def role_listener(kind: str, seconds: float) -> None:
    """Listen, then report own CPU over ``seconds`` once transforms flow."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from tf2_msgs.msg import TFMessage

    rclpy.init()
    node = rclpy.create_node(f"bench_tf_{kind}")
    count = [0]
    alive: list[object] = []
    if kind == "tf2":
        from tf2_ros import Buffer, TransformListener

        class CountingBuffer(Buffer):
            """The real buffer; only counts the transforms the listener hands it.

            The listener reads /tf's bytes itself (tf2_ros._wire) and gives the
            buffer each message's transforms at once, through ``_set_entries``.
            """

            def _set_entries(self, entries: list[Any], authority: str, is_static: bool) -> None:
                count[0] += len(entries)
                super()._set_entries(entries, authority, is_static)

        alive.append(TransformListener(CountingBuffer(), node))  # kept: dropping it unsubscribes
    else:
        size = RATE_HZ * CACHE_S
        store: dict[str, np.ndarray] = {}
        heads: dict[str, int] = {}

        def on_tf(data: TFMessage) -> None:
            for t in data.transforms:
                row = store.get(t.child_frame_id)
                if row is None:
                    row = store[t.child_frame_id] = np.zeros((size, 8))
                    heads[t.child_frame_id] = 0
                i = heads[t.child_frame_id]
                tr, q = t.transform.translation, t.transform.rotation
                row[i % size] = (
                    t.header.stamp.sec + t.header.stamp.nanosec * 1e-9,
                    tr.x, tr.y, tr.z, q.x, q.y, q.z, q.w,
                )  # fmt: skip
                heads[t.child_frame_id] = i + 1
            count[0] += len(data.transforms)

        node.create_subscription(TFMessage, "/tf", on_tf, 100)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    deadline = time.monotonic() + 20
    while count[0] == 0 and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.1)
    warm = time.monotonic() + 1.0
    while time.monotonic() < warm:
        executor.spin_once(timeout_sec=0.1)
    c0, w0, n0 = time.process_time(), time.monotonic(), count[0]
    end = w0 + seconds
    while time.monotonic() < end:
        executor.spin_once(timeout_sec=0.1)
    c1, w1, n1 = time.process_time(), time.monotonic(), count[0]
    print(
        json.dumps(
            {"cpu_percent": 100 * (c1 - c0) / (w1 - w0), "received_per_s": (n1 - n0) / (w1 - w0)}
        ),
        flush=True,
    )
    executor.shutdown()
    node.destroy_node()
    rclpy.try_shutdown()


def ingest(seconds: float) -> dict[str, float]:
    base = [sys.executable, "-m", "bench.tf2_lookup"]
    pub = subprocess.Popen([*base, "--role", "publisher", "--seconds", str(seconds + 8)])
    listeners = {
        kind: subprocess.Popen(
            [*base, "--role", kind, "--seconds", str(seconds)], stdout=subprocess.PIPE, text=True
        )
        for kind in ("tf2", "numpy")
    }
    out: dict[str, float] = {}
    try:
        for kind, proc in listeners.items():
            text, _ = proc.communicate(timeout=seconds + 40)
            res = json.loads(text.strip().splitlines()[-1])
            out[f"{kind}_ingest_cpu_percent"] = res["cpu_percent"]
            out[f"{kind}_received_per_s"] = res["received_per_s"]
    finally:
        everyone: list[subprocess.Popen[Any]] = [pub, *listeners.values()]
        for proc in everyone:
            if proc.poll() is None:
                proc.kill()
            proc.wait()
    for kind in listeners:
        if out[f"{kind}_received_per_s"] < 0.9 * INGEST_PER_S:
            raise RuntimeError(
                f"the {kind} listener received {out[f'{kind}_received_per_s']:.0f} "
                f"transforms/s of {INGEST_PER_S} (the other: "
                f"{ {k: round(v) for k, v in out.items() if k.endswith('received_per_s')} })"
            )
    out["ingest_ratio"] = out["tf2_ingest_cpu_percent"] / out["numpy_ingest_cpu_percent"]
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=8.0)
    parser.add_argument("--lookups", type=int, default=5000)
    parser.add_argument("--role", choices=("publisher", "tf2", "numpy"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.role == "publisher":
        role_publisher(args.seconds)
        return 0
    if args.role:
        role_listener(args.role, args.seconds)
        return 0
    require_private_netns("tf2_lookup")
    configure_dds(71)
    figures: dict[str, Any] = {}
    errors: list[str] = []
    try:
        figures.update(lookup_latency(args.lookups))
        print(
            f"lookup_transform, 20 frames, full 10 s cache at 100 Hz: p50 "
            f"{figures['tf2_lookup_p50_us']:.1f} us, p99 {figures['tf2_lookup_p99_us']:.1f} us "
            f"(numpy: p50 {figures['numpy_lookup_p50_us']:.1f} us; aim p50 <= {AIM_LOOKUP_US})",
            flush=True,
        )
    except Exception as exc:
        errors.append(f"lookup: {exc}")
    try:
        figures.update(ingest(args.seconds))
        print(
            f"ingest {INGEST_PER_S} transforms/s: tf2 {figures['tf2_ingest_cpu_percent']:.1f} % "
            f"of a core, numpy subscriber {figures['numpy_ingest_cpu_percent']:.1f} % "
            f"(aim <= {AIM_INGEST_PERCENT} %)",
            flush=True,
        )
    except Exception as exc:
        errors.append(f"ingest: {exc}")
    if errors:
        figures["error"] = "; ".join(errors)
    print(json.dumps(rounded(figures)), flush=True)
    return 1 if errors else 0


if __name__ == "__main__":
    raise SystemExit(main())
