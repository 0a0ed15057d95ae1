"""Benchmark: what a classroom costs per learner, and what the teacher page costs as N grows.

For N = 1, 5, 10, 20 learners, ``ros2-classroom classroom --learners N`` runs
(warm start, the default: every dashboard a fork of one warm parent,
``app/warm_start.py``) with one simulated browser on every learner dashboard
and one on the teacher page (``tests/wire_client.py``: viser's wire protocol
without a real browser, so the figures are the servers' cost, not
Chromium's). Each learner starts the catalog's ``talker`` and ``listener``
from their dashboard's Nodes tool, as issue 43's class does (``--nodes``; an
empty list for idle learners without nodes). Once the teacher page lists
everyone, every node runs and start-up has settled, every process of the
class is sampled with psutil over the same seconds: CPU (user + system, % of
one core) and memory (RSS, and PSS, which shares the common libraries, and
the warm parent's pages, fairly between processes).

Per learner: the dashboard alone (aims of issue 43: PSS at most 80 MB, idle
CPU at most 1.5 % of a core), and the learner whole: the whole class (the
classroom's teacher page, the warm parent, every dashboard and every node)
divided by N, so shared costs are spread over the class. From the learner
whole:

- ``classroom_learners_per_core`` = ``CORE_SHARE`` (50 %) of a core / a
  learner's idle CPU: half of every core is kept for what idle figures do not
  show (learners starting nodes, grading, building, the system);
- ``classroom_learners_per_gb`` = 1024 MB / a learner's PSS (no headroom
  here: the README's capacity table keeps the system's share aside).

Both are for the largest class measured (the JSON's top level); each class
size's figures are in ``rows``. A lone ``serve`` (no classroom, no progress
beacon, no nodes) is measured first, so the beacon's own cost shows.

Run: ``.venv/bin/python tests/run.py --bench classroom_footprint [--counts 1,5]
[--seconds S] [--nodes talker,listener]``. The last line printed is one JSON
object; a figure that cannot be measured is NaN with a ``FAILED:`` line, and
the benchmark exits 1.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import statistics
import sys
import time
from collections.abc import Sequence
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
NODES_SETTLE_SEC = 8.0  # and the nodes' start, discovery and first messages
CORE_SHARE = 0.5  # of each core, for idle learners; the rest is headroom
DASHBOARD_PSS_AIM_MB = 80.0
DASHBOARD_CPU_AIM_PERCENT = 1.5


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


def learners_per_core(learner_cpu_percent: float, share: float = CORE_SHARE) -> float:
    """Idle learners one core carries when they may take ``share`` of it (NaN: no figure)."""
    if not learner_cpu_percent > 0:  # also NaN
        return math.nan
    return 100.0 * share / learner_cpu_percent


def learners_per_gb(learner_pss_mb: float) -> float:
    """Learners whose PSS fits in 1 GB (1024 MB); NaN without a figure."""
    if not learner_pss_mb > 0:
        return math.nan
    return 1024.0 / learner_pss_mb


def sample_tree(root_pid: int, seconds: float) -> dict[int, dict[str, Any]]:
    """CPU % of one core and memory (RSS, PSS in MB) of ``root_pid`` and every process under
    it, over the same ``seconds``; a process that ends meanwhile is left out."""
    import psutil

    root = psutil.Process(root_pid)
    procs = [root, *root.children(recursive=True)]
    before: dict[int, tuple[Any, Any]] = {}
    for proc in procs:
        try:
            before[proc.pid] = (proc, proc.cpu_times())
        except psutil.Error:
            continue
    t0 = time.monotonic()
    time.sleep(seconds)
    elapsed = time.monotonic() - t0
    out: dict[int, dict[str, Any]] = {}
    for pid, (proc, times) in before.items():
        try:
            after = proc.cpu_times()
            memory = proc.memory_full_info()
            cmdline = " ".join(proc.cmdline())
        except psutil.Error:
            continue
        busy = (after.user - times.user) + (after.system - times.system)
        out[pid] = {
            "cpu_percent": 100.0 * busy / elapsed,
            "rss_mb": memory.rss / 2**20,
            "pss_mb": memory.pss / 2**20,
            "cmdline": cmdline,
        }
    return out


def start_nodes(clients: list[Any], nodes: Sequence[str]) -> None:
    """Each learner starts ``nodes`` from their dashboard's Nodes tool, as a learner does."""
    from tests.faults.helpers import choose

    for client in clients:
        deadline = time.monotonic() + 60.0
        while not (client.find("Catalog node", "GuiDropdownMessage") and client.find("Start")):
            if time.monotonic() > deadline:
                raise SystemExit(f"FAILED: no Nodes tool on {client.url}")
            time.sleep(0.2)
        for node in nodes:
            choose(client, "Catalog node", node)
            time.sleep(0.3)  # the choice is in before the click
            client.click("Start")
            time.sleep(0.3)


def nodes_running(clients: list[Any], nodes: Sequence[str], timeout: float) -> None:
    """Every learner's dashboard says each of ``nodes`` is running."""
    from tests.faults.helpers import overview

    deadline = time.monotonic() + timeout
    while True:
        waiting = [
            f"{client.url} {node}"
            for client in clients
            for node in nodes
            if f"{node} | ● running" not in overview(client)
        ]
        if not waiting:
            return
        if time.monotonic() > deadline:
            raise SystemExit(f"FAILED: not running after {timeout:.0f} s: {', '.join(waiting[:5])}")
        time.sleep(0.5)


def classroom(learners: int, seconds: float, nodes: Sequence[str] = ()) -> dict[str, Any]:
    """One class of ``learners``, each running ``nodes`` (none: idle learners, as
    ``bench/hub_spawn.py`` compares a hub learner with); the figures of its processes."""
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
        wanted = f"**{learners} learner{'s' if learners != 1 else ''}**"
        deadline = time.monotonic() + 60.0
        while wanted not in teacher.markdown():
            if time.monotonic() > deadline:
                raise SystemExit(f"FAILED: the teacher page never listed {learners} learners")
            time.sleep(0.2)
        if nodes:
            start_nodes(clients, nodes)
            nodes_running(clients, nodes, 60.0 + 6.0 * learners)
            time.sleep(NODES_SETTLE_SEC)
        clients.append(teacher)
        time.sleep(SETTLE_SEC)
        children = psutil.Process(room.pid).children()
        # The learners' dashboards; the warm parent they fork from (app/warm_start.py) counts
        # in the whole class, not as a dashboard.
        dashboards = [p.pid for p in children if "serve" in p.cmdline()]
        owner = {c.pid: d for d in dashboards for c in psutil.Process(d).children(recursive=True)}
        figures = sample_tree(room.pid, seconds)
        frames = teacher.frames
    finally:
        for client in clients:
            client.close()
        stop(room, timeout=30.0)
    each = [figures[pid] for pid in dashboards if pid in figures]
    node_procs = [f for pid, f in figures.items() if pid in owner]
    warm = [  # the warm parent, and whatever else the classroom runs beside the dashboards
        f for pid, f in figures.items() if pid not in (room.pid, *dashboards) and pid not in owner
    ]
    if len(each) != learners:
        raise SystemExit(f"FAILED: {len(each)} dashboards sampled, not {learners}")
    total_cpu = sum(f["cpu_percent"] for f in figures.values())
    total_pss = sum(f["pss_mb"] for f in figures.values())
    return {
        "learners": learners,
        "boot_sec": boot_sec,
        "dashboard_cpu_percent": statistics.fmean(f["cpu_percent"] for f in each),
        "dashboard_rss_mb": statistics.fmean(f["rss_mb"] for f in each),
        "dashboard_pss_mb": statistics.fmean(f["pss_mb"] for f in each),
        "node_processes_per_learner": len(node_procs) / learners,
        "nodes_cpu_percent_per_learner": sum(f["cpu_percent"] for f in node_procs) / learners,
        "nodes_pss_mb_per_learner": sum(f["pss_mb"] for f in node_procs) / learners,
        "teacher_cpu_percent": figures[room.pid]["cpu_percent"],
        "teacher_rss_mb": figures[room.pid]["rss_mb"],
        "teacher_pss_mb": figures[room.pid]["pss_mb"],
        "teacher_frames": frames,
        "warm_parent_pss_mb": sum(f["pss_mb"] for f in warm),
        "total_cpu_percent": total_cpu,
        "total_pss_mb": total_pss,
        "learner_cpu_percent": total_cpu / learners,
        "learner_pss_mb": total_pss / learners,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench classroom_footprint")
    parser.add_argument("--counts", default="1,5,10,20", help="class sizes, comma-separated")
    parser.add_argument("--seconds", type=float, default=10.0, help="sampling window")
    parser.add_argument(
        "--nodes", default="talker,listener", help="catalog nodes each learner starts ('' none)"
    )
    args = parser.parse_args(argv)
    counts = [int(n) for n in args.counts.split(",") if n.strip()]
    nodes = [n.strip() for n in args.nodes.split(",") if n.strip()]
    require_private_netns("classroom_footprint")
    configure_dds(40)
    failures: list[str] = []
    load_start = os.getloadavg()[0]  # others may share the cores

    lone = lone_dashboard(args.seconds)
    print(
        f"one dashboard alone (no beacon, no nodes): {lone['cpu_percent']:.1f} % of a core, "
        f"RSS {lone['rss_mb']:.0f} MB, PSS {lone['pss_mb']:.0f} MB",
        flush=True,
    )
    print(
        f"each learner runs: {', '.join(nodes) or 'no nodes'}; learners/core at "
        f"{CORE_SHARE:.0%} of each core, from a learner's share of the whole class",
        flush=True,
    )
    rows = []
    print(
        "| learners | dashboard CPU % | dashboard PSS MB | nodes PSS MB / learner "
        "| learner CPU % | learner PSS MB | teacher CPU % | whole class CPU % "
        "| whole class PSS MB | learners/core | learners/GB |",
        flush=True,
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|", flush=True)
    for n in counts:
        try:
            row = classroom(n, args.seconds, nodes)
        except (Exception, SystemExit) as exc:  # this class size not measured: say why
            failures.append(f"class of {n}: {str(exc).removeprefix('FAILED: ')}")
            continue
        row["learners_per_core"] = learners_per_core(row["learner_cpu_percent"])
        row["learners_per_gb"] = learners_per_gb(row["learner_pss_mb"])
        rows.append(row)
        print(
            f"| {n} | {row['dashboard_cpu_percent']:.2f} | {row['dashboard_pss_mb']:.0f} "
            f"| {row['nodes_pss_mb_per_learner']:.0f} | {row['learner_cpu_percent']:.2f} "
            f"| {row['learner_pss_mb']:.0f} | {row['teacher_cpu_percent']:.1f} "
            f"| {row['total_cpu_percent']:.0f} | {row['total_pss_mb']:.0f} "
            f"| {row['learners_per_core']:.1f} | {row['learners_per_gb']:.1f} |",
            flush=True,
        )
    largest = max(rows, key=lambda r: r["learners"], default={})
    result: dict[str, Any] = {
        "seconds": args.seconds,
        "nodes_per_learner": ",".join(nodes),
        "core_share": CORE_SHARE,
        "load_average_start": load_start,
        "load_average_end": os.getloadavg()[0],
        "lone_dashboard_cpu_percent": lone["cpu_percent"],
        "lone_dashboard_pss_mb": lone["pss_mb"],
        "classroom_learners": largest.get("learners", 0),
        "rows": [rounded(r, 2) for r in rows],
    }
    for key in (
        "dashboard_pss_mb",
        "dashboard_cpu_percent",
        "learner_pss_mb",
        "learner_cpu_percent",
        "learners_per_core",
        "learners_per_gb",
    ):
        result[f"classroom_{key}"] = float(largest.get(key, math.nan))
    if largest:
        pss, cpu = result["classroom_dashboard_pss_mb"], result["classroom_dashboard_cpu_percent"]
        print(
            f"class of {largest['learners']}: PSS per dashboard {pss:.0f} MB "
            f"(aim <= {DASHBOARD_PSS_AIM_MB:.0f}), idle CPU per dashboard {cpu:.2f} % of a core "
            f"(aim <= {DASHBOARD_CPU_AIM_PERCENT}); a learner with its nodes and a share of the "
            f"class: {result['classroom_learner_pss_mb']:.0f} MB PSS, "
            f"{result['classroom_learner_cpu_percent']:.2f} % of a core -> "
            f"{result['classroom_learners_per_core']:.1f} learners per core, "
            f"{result['classroom_learners_per_gb']:.1f} per GB",
            flush=True,
        )
    else:
        failures.append("no class size measured")
    for failure in failures:
        print(f"FAILED: {failure}", flush=True)
    print(json.dumps(rounded(result, 2), sort_keys=True))
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
