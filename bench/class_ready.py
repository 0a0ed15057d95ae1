"""Benchmark: a class arrives at once; every learner's dashboard ready, warm start against cold.

``ros2-classroom classroom --learners N`` starts N learner dashboards
together (and the teacher page), as at 9 a.m. Per learner, *ready* is the
time from the command's start to the moment a websocket client on that
learner's port has been sent the dashboard's page (its header and its tools,
as bench/hub_spawn.py counts it): the page polled every POLL_SEC, then a
websocket opened (tests/wire_client.py). p50 and p95 over the learners of
all rounds.

Warm start (app/warm_start.py: one warm parent pays the imports, each
dashboard is a fork of it) is measured against cold start
(``CLASSROOM_COLD_START=1``: every dashboard imports everything itself, as
before) in the same run, rounds alternating so a load spike hits both
alike. A learner never ready within the deadline is a failure, said on a
``FAILED:`` line; its figures are then not reported.

Run: ``.venv/bin/python tests/run.py --bench class_ready [--counts 5,10] [--rounds N]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from pathlib import Path
from typing import Any

from app.ui.opening import OPENING_WORDS
from bench._common import (
    LOGS,
    configure_dds,
    percentile,
    ratio,
    require_private_netns,
    rounded,
    spawn,
    stop,
)

POLL_SEC = 0.2
MODES = ("cold", "warm")  # cold first in each round: the baseline


def _free_block(count: int) -> int:
    """A first port with ``count`` free ports after it and one free before (the teacher's).

    Below the ephemeral range: a client polling a port nobody listens on yet may be
    given that very port as its own and connect to itself (TCP's simultaneous open),
    which then holds the port the dashboard was to listen on.
    """
    low = int(Path("/proc/sys/net/ipv4/ip_local_port_range").read_text().split()[0])
    while True:
        base = random.randrange(10_000, low - count - 1)
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


def _ready_one(url: str, started: float, deadline: float, out: dict[str, Any]) -> None:
    """Seconds from ``started`` until ``url`` serves the dashboard's page over its websocket."""
    from tests.wire_client import WireClient

    client = None
    try:
        while True:
            if time.monotonic() > deadline:
                raise TimeoutError("the page never answered")
            try:
                with urllib.request.urlopen(url, timeout=5) as page:
                    if page.status == 200:
                        break
            except OSError:
                pass
            time.sleep(POLL_SEC)
        while client is None:
            try:
                client = WireClient(url)
            except (OSError, TimeoutError):
                if time.monotonic() > deadline:
                    raise
                time.sleep(POLL_SEC)
        # The whole dashboard: serve's page answers while it is still being built.
        while not (
            "Domain id" in (text := client.markdown())
            and "ros2" in text
            and OPENING_WORDS not in text
        ):
            if time.monotonic() > deadline:
                raise TimeoutError("the dashboard never sent its page")
            time.sleep(0.02)
        out["seconds"] = time.monotonic() - started
    except Exception as error:  # reported as a failure, never swallowed
        out["error"] = f"{type(error).__name__}: {error}"
    finally:
        if client is not None:
            client.close()


def one_class(learners: int, mode: str, round_no: int) -> dict[str, Any]:
    """Start a class of ``learners``; each one's seconds to a ready page, and what failed."""
    base = _free_block(learners)
    env = {"CLASSROOM_COLD_START": "1" if mode == "cold" else "0"}
    progress = LOGS / f"bench-class-ready-{mode}-{learners}-{round_no}"
    shutil.rmtree(progress, ignore_errors=True)  # a class that has done nothing yet
    started = time.monotonic()
    room, log = _spawn_room(learners, base, progress, env, f"{progress.name}.log")
    deadline = started + 60.0 + 10.0 * learners
    results: list[dict[str, Any]] = [{} for _ in range(learners)]
    threads = [
        threading.Thread(
            target=_ready_one,
            args=(f"http://127.0.0.1:{base + i}", started, deadline, results[i]),
        )
        for i in range(learners)
    ]
    try:
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    finally:
        stop(room, timeout=30.0)
    text = log.read_text(errors="replace")
    imports = re.search(r"imported everything once, in ([0-9.]+) s", text)
    errors = [f"learner{i + 1}: {r['error']}" for i, r in enumerate(results) if "error" in r]
    if mode == "warm" and imports is None:
        errors.append("the classroom did not start warm: " + _first_warm_line(text))
    return {
        "seconds": [r["seconds"] for r in results if "seconds" in r],
        "errors": errors,
        "warm_parent_import_s": float(imports.group(1)) if imports else math.nan,
    }


def _spawn_room(
    learners: int, base: int, progress: Path, env: dict[str, str], log_name: str
) -> tuple[subprocess.Popen[bytes], Path]:
    """``classroom --learners N`` as bench._common.spawn starts it, with ``env`` added."""
    saved = {k: os.environ.get(k) for k in env}
    os.environ.update(env)  # spawn() copies os.environ
    try:
        return spawn(
            [sys.executable, "-m", "app", "classroom", "--learners", str(learners),
             "--base-port", str(base), "--base-domain-id", "1", "--classroom-domain-id", "101",
             "--progress-dir", str(progress)],
            log_name,
        )  # fmt: skip
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def _first_warm_line(text: str) -> str:
    return next((line for line in text.splitlines() if "arm start" in line), "no warm-start line")


def run(counts: list[int], rounds: int) -> tuple[dict[str, Any], list[str]]:
    require_private_netns("class_ready")
    configure_dds(47)
    rows: list[dict[str, Any]] = []
    failures: list[str] = []
    for n in counts:
        seconds: dict[str, list[float]] = {mode: [] for mode in MODES}
        imports: list[float] = []
        for k in range(rounds):
            for mode in MODES:
                got = one_class(n, mode, k)
                seconds[mode] += got["seconds"]
                if not math.isnan(got["warm_parent_import_s"]):
                    imports.append(got["warm_parent_import_s"])
                failures += [f"{n} learners, {mode}, round {k + 1}: {e}" for e in got["errors"]]
                shown = sorted(got["seconds"])
                print(
                    f"{n} learners, round {k + 1}, {mode:4s}: ready in "
                    + (f"{shown[0]:.1f}..{shown[-1]:.1f} s" if shown else "-")
                    + (f" ({len(got['errors'])} failures)" if got["errors"] else ""),
                    flush=True,
                )
        complete = {m: len(seconds[m]) == n * rounds for m in MODES}
        row: dict[str, Any] = {"learners": n, "rounds": rounds}
        for mode in MODES:
            values = seconds[mode] if complete[mode] else []
            prefix = "" if mode == "warm" else "cold_"
            row[f"{prefix}p50_s"] = percentile(values, 50)
            row[f"{prefix}p95_s"] = percentile(values, 95)
            row[f"{prefix}max_s"] = max(values) if values else math.nan
        row["p95_ratio"] = ratio(row["p95_s"], row["cold_p95_s"])
        row["p50_ratio"] = ratio(row["p50_s"], row["cold_p50_s"])
        row["warm_parent_import_s"] = percentile(imports, 50)
        rows.append(row)
    largest = max(rows, key=lambda r: r["learners"])
    result = {
        "class_ready_learners": largest["learners"],
        "class_ready_p50_s": largest["p50_s"],
        "class_ready_p95_s": largest["p95_s"],
        "class_ready_cold_p50_s": largest["cold_p50_s"],
        "class_ready_cold_p95_s": largest["cold_p95_s"],
        "class_ready_p50_ratio": largest["p50_ratio"],
        "class_ready_p95_ratio": largest["p95_ratio"],
        "class_ready_warm_parent_import_s": largest["warm_parent_import_s"],
        "rows": [rounded(r, 2) for r in rows],
    }
    return result, failures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench class_ready")
    parser.add_argument("--counts", default="5,10", help="class sizes, comma-separated")
    parser.add_argument("--rounds", type=int, default=2, help="rounds per class size and mode")
    args = parser.parse_args(argv)
    counts = [int(n) for n in args.counts.split(",") if n.strip()]
    signal.signal(signal.SIGTERM, signal.default_int_handler)  # a timeout stops the classes
    result, failures = run(counts, args.rounds)
    print(
        "| learners | warm p50 / p95 s | cold p50 / p95 s | p95 warm/cold | warm parent imports s |"
    )
    print("|---|---|---|---|---|")
    for row in result["rows"]:

        def pair(a: Any, b: Any) -> str:
            return " / ".join("–" if v is None else f"{v:.1f}" for v in (a, b))

        print(
            f"| {row['learners']} | {pair(row['p50_s'], row['p95_s'])} "
            f"| {pair(row['cold_p50_s'], row['cold_p95_s'])} "
            f"| {'–' if row['p95_ratio'] is None else format(row['p95_ratio'], '.2f')} "
            f"| {'–' if row['warm_parent_import_s'] is None else row['warm_parent_import_s']} |",
            flush=True,
        )
    for failure in failures:
        print(f"FAILED: {failure}", flush=True)
    print(json.dumps(rounded(result, 2), sort_keys=True))
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
