"""Benchmark: a class on JupyterHub in both single-user modes, beside a `classroom` class.

For N learners (1, 5, 20 by default) a real JupyterHub (tests/hub/local_hub.py:
deploy/jupyterhub_config.py, configurable-http-proxy, ClassroomLocalSpawner)
is asked to start all N servers at once, as a class arriving together, once
per single-user mode:

- lean (``CLASSROOM_SINGLEUSER=dashboard``, the README's recommendation): the
  dashboard is the learner's server and does the hub's OAuth itself;
- lab: a Jupyter server (JupyterLab) whose jupyter-server-proxy starts the
  dashboard on the first request to ``/user/<name>/ros2-classroom/``;
- lean_cold: lean with the spawner's warm start off, so each dashboard pays
  its own imports: ``hub_warm_spawn_speedup`` is its p50 over lean's.

Per learner, spawn -> dashboard ready is the time from the spawn request to
the moment a websocket client, through the hub's proxy, is sent the
dashboard's GUI: the hub is asked once a second whether the server is up,
then the page is fetched (in the lab mode that makes jupyter-server-proxy
start the dashboard), then the websocket opened. p50 and p95 over the learners.

Then, idle with one client each (tests/wire_client.py, through the proxy),
every process is sampled over the same seconds: each learner's single-user
server and dashboard (one process in the lean mode), and the hub's shared
processes (hub, proxy, teacher service). The baseline is ``classroom
--learners N`` in the same run (bench/classroom_footprint.py: N dashboards
and the teacher page in one process). Per learner = the whole class's total
/ N on each side, so the hub's shared processes count, spread over the
class; the overhead is the hub side's per-learner PSS (and CPU) over the
baseline's. The summary's ``hub_*`` figures are the lean mode's at the
largest class; ``hub_lab_*`` the lab mode's.

A class size the machine cannot hold (memory) is a failure row with the reason.
Run: ``.venv/bin/python tests/run.py --bench hub_spawn [--counts 1,5,20]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import threading
import time
from typing import Any

from app.ui.opening import OPENING_WORDS
from bench._common import LOGS, configure_dds, percentile, require_private_netns, rounded, sample

SETTLE_SEC = 4.0
POLL_SEC = 1.0  # how often the hub is asked whether a server is ready
# The sides run one after another: the largest (a lab learner, ~300 MB) with headroom.
MB_PER_LEARNER = 450
# The first is the README's recommendation; lean_cold is lean with warm start off
# (CLASSROOM_COLD_START=1: every dashboard imports everything itself), its baseline.
MODES = ("lean", "lab", "lean_cold")
SINGLEUSER = {"lean": "dashboard", "lab": "lab", "lean_cold": "dashboard"}


def _ready_one(hub: Any, user: str, started: float, out: dict[str, Any]) -> None:
    from tests.hub.local_hub import ADMIN_TOKEN
    from tests.wire_client import WireClient

    try:
        hub.spawn(user)
        deadline = started + 240.0
        # Once a second: 20 learners polled every 0.1 s kept the hub so busy (200 requests
        # a second) that its own call to the proxy timed out and it stopped a server.
        while not hub.server_ready(user):
            if time.monotonic() > deadline:
                raise TimeoutError("the hub never reported the server ready")
            time.sleep(POLL_SEC)
        path = f"/user/{user}/" if hub.lean else f"/user/{user}/ros2-classroom/"
        status, body = hub.api("GET", path, timeout=180.0)
        if status != 200 or "viser" not in str(body).lower():
            raise RuntimeError(f"the Classroom page answered {status}")
        ws = f"http://127.0.0.1:{hub.port}{path}"
        client = None
        while client is None:  # a websocket handshake may take over 10 s on busy cores
            try:
                client = WireClient(ws, headers={"Authorization": f"token {ADMIN_TOKEN}"})
            except TimeoutError:
                if time.monotonic() > deadline:
                    raise
        # The whole dashboard: serve's page answers while it is still being built.
        while "ros2" not in (text := client.markdown()) or OPENING_WORDS in text:
            if time.monotonic() > deadline:
                raise TimeoutError("the dashboard never sent its GUI")
            time.sleep(0.05)
        out["seconds"] = time.monotonic() - started
        out["client"] = client
    except Exception as error:  # reported in the row, never swallowed
        out["error"] = f"{type(error).__name__}: {error}"


def hub_class(learners: int, seconds: float, mode: str) -> dict[str, Any]:
    import psutil

    from tests.hub.local_hub import LocalHub

    state = LOGS / f"bench-hub-{mode}-{learners}"
    shutil.rmtree(state, ignore_errors=True)
    users = [f"learner{i + 1}" for i in range(learners)]
    env = dict(os.environ)
    if mode == "lean_cold":
        env["CLASSROOM_COLD_START"] = "1"
    hub = LocalHub(
        state,
        env,
        learners=users,
        teachers=[],
        first_domain_id=1,
        singleuser=SINGLEUSER[mode],
    )
    results: dict[str, dict[str, Any]] = {u: {} for u in users}
    try:
        hub.wait_ready()
        started = time.monotonic()
        threads = [
            threading.Thread(target=_ready_one, args=(hub, u, started, results[u])) for u in users
        ]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        errors = {u: r["error"] for u, r in results.items() if "error" in r}
        if errors:
            raise RuntimeError(f"{len(errors)} of {learners} never got ready: {errors}")
        time.sleep(SETTLE_SEC)
        servers, dashboards = hub.single_user_servers(), hub.dashboards()
        shared = {"hub": hub.proc.pid}
        for proc in psutil.Process(hub.proc.pid).children():
            cmd = " ".join(proc.cmdline())
            if "configurable-http-proxy" in cmd:
                shared["proxy"] = proc.pid
            elif "app.hub.teacher_service" in cmd:
                shared["teacher_service"] = proc.pid
        pids = {**shared, **{f"dashboard:{u}": dashboards[u].pid for u in users}}
        if not hub.lean:  # the Jupyter server in front of each dashboard
            pids.update({f"server:{u}": servers[u].pid for u in users})
        figures = sample(pids, seconds)
    finally:
        for result in results.values():
            if "client" in result:
                result["client"].close()
        left = hub.stop()
        if left:
            print(f"warning: killed {len(left)} processes that outlived the hub", flush=True)
    spawn = [results[u]["seconds"] for u in users]

    def mean(prefix: str, key: str) -> float:
        if prefix == "server" and hub.lean:
            return 0.0  # the dashboard is the server
        return statistics.fmean(figures[f"{prefix}:{u}"][key] for u in users)

    return {
        "mode": mode,
        "learners": learners,
        "spawn_p50_s": percentile(spawn, 50),
        "spawn_p95_s": percentile(spawn, 95),
        "server_cpu_percent": mean("server", "cpu_percent"),
        "server_pss_mb": mean("server", "pss_mb"),
        "dashboard_cpu_percent": mean("dashboard", "cpu_percent"),
        "dashboard_pss_mb": mean("dashboard", "pss_mb"),
        "dashboard_rss_mb": mean("dashboard", "rss_mb"),  # what a pod's memory limit counts
        "server_rss_mb": mean("server", "rss_mb"),
        "shared_cpu_percent": sum(figures[n]["cpu_percent"] for n in shared),
        "shared_pss_mb": sum(figures[n]["pss_mb"] for n in shared),
        "per_learner_cpu_percent": sum(f["cpu_percent"] for f in figures.values()) / learners,
        "per_learner_pss_mb": sum(f["pss_mb"] for f in figures.values()) / learners,
    }


def classroom_class(learners: int, seconds: float) -> dict[str, Any]:
    from bench.classroom_footprint import classroom

    row = classroom(learners, seconds)
    return {
        "per_learner_cpu_percent": row["total_cpu_percent"] / learners,
        "per_learner_pss_mb": row["total_pss_mb"] / learners,
        "dashboard_cpu_percent": row["dashboard_cpu_percent"],
        "dashboard_pss_mb": row["dashboard_pss_mb"],
    }


def _room_for(learners: int) -> str:
    import psutil

    available = psutil.virtual_memory().available / 2**20
    needed = learners * MB_PER_LEARNER
    if available < needed:
        return f"needs about {needed} MB free, the machine has {available:.0f} MB"
    return ""


def _deep_round(row: dict[str, Any]) -> dict[str, Any]:
    return {k: _deep_round(v) if isinstance(v, dict) else v for k, v in rounded(row, 2).items()}


def _measure(n: int, seconds: float) -> dict[str, Any]:
    """Both hub modes and the classroom baseline for one class size (a failure row on error)."""
    row: dict[str, Any] = {"learners": n}
    reason = _room_for(n)
    if reason:
        row["error"] = reason
        return row
    try:
        for mode in MODES:
            row[mode] = hub_class(n, seconds, mode)
        base = row["classroom"] = classroom_class(n, seconds)
        for mode in MODES:
            hub = row[mode]
            hub["memory_overhead_percent"] = 100.0 * (
                hub["per_learner_pss_mb"] / base["per_learner_pss_mb"] - 1.0
            )
            hub["cpu_overhead_core_percent"] = (
                hub["per_learner_cpu_percent"] - base["per_learner_cpu_percent"]
            )
    except Exception as error:  # a failure row, with the reason
        row["error"] = f"{type(error).__name__}: {error}"[:500]
    return row


def _print_row(row: dict[str, Any]) -> None:
    n = row["learners"]
    if "error" in row:
        print(f"| {n} | failed: {row['error']} ||||||||", flush=True)
        return
    base = row["classroom"]
    for mode in MODES:
        hub = row[mode]
        server = f"{hub['server_pss_mb']:.0f} + " if mode == "lab" else ""
        print(
            f"| {n} | {mode} | {hub['spawn_p50_s']:.1f} / {hub['spawn_p95_s']:.1f} "
            f"| {hub['per_learner_pss_mb']:.0f} ({server}{hub['dashboard_pss_mb']:.0f} + "
            f"{hub['shared_pss_mb'] / n:.0f}) "
            f"| {base['per_learner_pss_mb']:.0f} | {hub['memory_overhead_percent']:+.0f} % "
            f"| {hub['per_learner_cpu_percent']:.1f} | {base['per_learner_cpu_percent']:.1f} "
            f"| {hub['cpu_overhead_core_percent']:+.1f} |",
            flush=True,
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench hub_spawn")
    parser.add_argument("--counts", default="1,5,20", help="class sizes, comma-separated")
    parser.add_argument("--seconds", type=float, default=10.0, help="sampling window")
    args = parser.parse_args(argv)
    counts = [int(n) for n in args.counts.split(",") if n.strip()]
    require_private_netns("hub_spawn")
    configure_dds(45)
    LOGS.mkdir(parents=True, exist_ok=True)

    print(
        "| learners | mode | spawn→ready p50 / p95 s "
        "| hub learner PSS MB ([server +] dashboard + shared/N) "
        "| classroom learner PSS MB | memory overhead | hub learner CPU % | classroom CPU % "
        "| CPU overhead (% of a core) |",
        flush=True,
    )
    print("|---|---|---|---|---|---|---|---|---|", flush=True)
    rows: list[dict[str, Any]] = []
    for n in counts:
        row = _measure(n, args.seconds)
        rows.append(row)
        _print_row(row)
    good = [r for r in rows if "error" not in r]
    result: dict[str, Any] = {"seconds": args.seconds, "rows": [_deep_round(r) for r in rows]}
    if good:
        largest = max(good, key=lambda r: r["learners"])
        lean, lab, cold = largest["lean"], largest["lab"], largest["lean_cold"]
        result.update(
            hub_mode="lean",
            hub_spawn_p50_s=lean["spawn_p50_s"],
            hub_spawn_p95_s=lean["spawn_p95_s"],
            hub_memory_overhead_percent=lean["memory_overhead_percent"],
            hub_cpu_overhead_core_percent=lean["cpu_overhead_core_percent"],
            hub_lab_spawn_p50_s=lab["spawn_p50_s"],
            hub_lab_spawn_p95_s=lab["spawn_p95_s"],
            hub_lab_memory_overhead_percent=lab["memory_overhead_percent"],
            hub_lab_cpu_overhead_core_percent=lab["cpu_overhead_core_percent"],
            hub_learners_measured=largest["learners"],
            hub_cold_spawn_p50_s=cold["spawn_p50_s"],
            hub_cold_spawn_p95_s=cold["spawn_p95_s"],
            hub_warm_spawn_speedup=cold["spawn_p50_s"] / lean["spawn_p50_s"],
        )
    else:
        result["error"] = "no class size could be measured: " + "; ".join(
            f"{r['learners']}: {r['error']}" for r in rows
        )
    print(json.dumps(rounded(result, 2), sort_keys=True, default=str))
    return 0 if good else 1


if __name__ == "__main__":
    raise SystemExit(main())
