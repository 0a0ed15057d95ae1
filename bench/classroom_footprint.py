"""Benchmark: what a classroom costs per learner, and what the teacher page costs as N grows.

For N = 1, 5, 10, 20 learners, ``ros2-classroom classroom --learners N`` runs
with one simulated browser on every learner dashboard and one on the teacher
page (``tests/wire_client.py``: viser's wire protocol without a real browser,
so the figures are the servers' cost, not Chromium's). Once the teacher page
lists everyone and start-up has settled, every process is sampled with psutil
over the same seconds: CPU (user + system, % of one core) and memory (RSS,
and PSS, which shares the common libraries fairly between processes).

A lone ``serve`` (no classroom, no progress beacon) is measured first, so the
beacon's own cost shows. Learners per core = 100 / a dashboard's idle CPU %;
learners per GB = 1024 / a dashboard's PSS in MB. The idle learner runs no
tutorial nodes: each node a learner starts adds its own process on top.

Run: ``.venv/bin/python tests/run.py --bench classroom_footprint [--counts 1,5]
[--seconds S]``. The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import sys
import time
from typing import Any

from bench._common import (
    LOGS,
    configure_dds,
    free_port,
    require_private_netns,
    rounded,
    sample,
    spawn,
    start_dashboard,
    stop,
    wait_for_text,
)

SETTLE_SEC = 4.0  # start-up work and the first page's traffic are not idle


def _free_block(count: int) -> int:
    """A first port with ``count`` free ports after it and one free before (the teacher's)."""
    import socket

    while True:
        base = free_port()
        if base + count > 65535:
            continue
        ok = True
        for port in range(base - 1, base + count):
            with socket.socket() as probe:
                try:
                    probe.bind(("127.0.0.1", port))
                except OSError:
                    ok = False
                    break
        if ok:
            return base


def lone_dashboard(seconds: float) -> dict[str, float]:
    """One ``serve`` with one simulated browser: the dashboard without the beacon."""
    from tests.wire_client import WireClient

    dashboard, url = start_dashboard("bench-footprint-lone.log")
    try:
        client = WireClient(url)
        time.sleep(SETTLE_SEC)
        figures = sample({"dashboard": dashboard.pid}, seconds)["dashboard"]
        client.close()
    finally:
        stop(dashboard)
    return figures


def classroom(learners: int, seconds: float) -> dict[str, Any]:
    import psutil

    from tests.wire_client import WireClient

    base = _free_block(learners)
    progress = LOGS / f"bench-footprint-progress-{learners}"
    room, log = spawn(
        [sys.executable, "-m", "app", "classroom", "--learners", str(learners),
         "--base-port", str(base), "--base-domain-id", "1", "--classroom-domain-id", "101",
         "--progress-dir", str(progress)],
        f"bench-footprint-{learners}.log",
    )  # fmt: skip
    clients: list[WireClient] = []
    try:
        booted = time.monotonic()
        wait_for_text(room, log, "Press Ctrl+C", 60.0 + 10.0 * learners)
        boot_sec = time.monotonic() - booted
        text = log.read_text(errors="replace")
        urls = re.findall(r"learner\d+\s+(http://\S+)", text)
        teacher_url = re.search(r"Teacher page: (http://\S+)", text)
        assert teacher_url and len(urls) == learners, text
        clients = [WireClient(url) for url in urls]
        teacher = WireClient(teacher_url.group(1))
        clients.append(teacher)
        wanted = f"**{learners} learner{'s' if learners != 1 else ''}**"
        deadline = time.monotonic() + 60.0
        while wanted not in teacher.markdown():
            if time.monotonic() > deadline:
                raise SystemExit(f"the teacher page never listed {learners} learners")
            time.sleep(0.2)
        time.sleep(SETTLE_SEC)
        children = psutil.Process(room.pid).children()
        # The learners' dashboards; the warm parent they fork from (app/warm_start.py) counts
        # in the whole class, not as a dashboard.
        serving = [p for p in children if "serve" in p.cmdline()]
        dashboards = {f"d{i}": p.pid for i, p in enumerate(serving)}
        others = [p for p in children if p not in serving]
        warm = {f"warm_parent{i}": p.pid for i, p in enumerate(others)}
        figures = sample({"teacher": room.pid, **dashboards, **warm}, seconds)
        frames = teacher.frames
    finally:
        for client in clients:
            client.close()
        stop(room, timeout=30.0)
    each = [figures[name] for name in dashboards]
    return {
        "learners": learners,
        "boot_sec": boot_sec,
        "dashboard_cpu_percent": statistics.fmean(f["cpu_percent"] for f in each),
        "dashboard_rss_mb": statistics.fmean(f["rss_mb"] for f in each),
        "dashboard_pss_mb": statistics.fmean(f["pss_mb"] for f in each),
        "teacher_cpu_percent": figures["teacher"]["cpu_percent"],
        "teacher_rss_mb": figures["teacher"]["rss_mb"],
        "teacher_pss_mb": figures["teacher"]["pss_mb"],
        "teacher_frames": frames,
        "warm_parent_pss_mb": sum(figures[name]["pss_mb"] for name in warm),
        "total_cpu_percent": sum(f["cpu_percent"] for f in figures.values()),
        "total_pss_mb": sum(f["pss_mb"] for f in figures.values()),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench classroom_footprint")
    parser.add_argument("--counts", default="1,5,10,20", help="class sizes, comma-separated")
    parser.add_argument("--seconds", type=float, default=10.0, help="sampling window")
    args = parser.parse_args(argv)
    counts = [int(n) for n in args.counts.split(",") if n.strip()]
    require_private_netns("classroom_footprint")
    configure_dds(40)

    lone = lone_dashboard(args.seconds)
    print(
        f"one dashboard alone (no beacon): {lone['cpu_percent']:.1f} % of a core, "
        f"RSS {lone['rss_mb']:.0f} MB, PSS {lone['pss_mb']:.0f} MB",
        flush=True,
    )
    rows = []
    print(
        "| learners | dashboard CPU % | dashboard PSS MB | teacher CPU % | teacher RSS MB "
        "| whole class CPU % | whole class PSS MB | learners/core | learners/GB |",
        flush=True,
    )
    print("|---|---|---|---|---|---|---|---|---|", flush=True)
    for n in counts:
        row = classroom(n, args.seconds)
        row["learners_per_core"] = 100.0 / max(row["dashboard_cpu_percent"], 0.1)
        row["learners_per_gb"] = 1024.0 / row["dashboard_pss_mb"]
        rows.append(row)
        print(
            f"| {n} | {row['dashboard_cpu_percent']:.1f} | {row['dashboard_pss_mb']:.0f} "
            f"| {row['teacher_cpu_percent']:.1f} | {row['teacher_rss_mb']:.0f} "
            f"| {row['total_cpu_percent']:.0f} | {row['total_pss_mb']:.0f} "
            f"| {row['learners_per_core']:.1f} | {row['learners_per_gb']:.1f} |",
            flush=True,
        )
    result = {
        "seconds": args.seconds,
        "lone_dashboard_cpu_percent": lone["cpu_percent"],
        "lone_dashboard_pss_mb": lone["pss_mb"],
        "rows": [rounded(r, 2) for r in rows],
    }
    print(json.dumps(rounded(result, 2), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
