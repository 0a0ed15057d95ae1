"""Benchmark: ``ros2-classroom serve`` to the first page ready, against a bare viser + rclpy app.

Each round starts the process, waits for its "ready" line, then loads the
page in headless Chromium until the GUI has rendered (the dashboard's tabs;
the baseline's one line of text). The baseline is the least such an app can
be: ``rclpy.init``, one node, one ``viser.ViserServer`` with one markdown.
Rounds alternate, so a load spike hits both alike.

Run: ``.venv/bin/python tests/run.py --bench startup [--rounds N]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

from bench._common import (
    LOGS,
    configure_dds,
    free_port,
    launch_browser,
    ratio,
    require_private_netns,
    rounded,
    spawn,
    stop,
    summary,
    wait_for_text,
)

BARE_APP = """
import sys, threading
import rclpy, viser
from rclpy.node import Node
rclpy.init()
node = Node("bench_bare_app")
server = viser.ViserServer(host="127.0.0.1", port=int(sys.argv[1]), verbose=False)
server.gui.add_markdown("bare app")
print("bare app is ready", flush=True)
try:
    threading.Event().wait()
except KeyboardInterrupt:
    pass
finally:
    server.stop()
    rclpy.try_shutdown()
"""


def one_start(browser: Any, kind: str) -> tuple[float, float]:
    """(seconds to the ready line, seconds to the page rendered), from the spawn."""
    port = free_port()
    if kind == "dashboard":
        argv = [sys.executable, "-m", "app", "serve", "--port", str(port)]
        argv += ["--progress-dir", str(LOGS / "bench-progress")]
    else:
        argv = [sys.executable, "-c", BARE_APP, str(port)]
    t0 = time.monotonic()
    proc, log = spawn(argv, f"bench-startup-{kind}.log")
    try:
        ready = wait_for_text(proc, log, "is ready", 60) - t0
        context = browser.new_context(viewport={"width": 1400, "height": 900})
        page = context.new_page()
        page.goto(f"http://127.0.0.1:{port}")
        if kind == "dashboard":
            page.get_by_role("tab", name="Learn", exact=True).wait_for(timeout=60_000)
        else:
            page.get_by_text("bare app").wait_for(timeout=60_000)
        shown = time.monotonic() - t0
        context.close()
        return ready, shown
    finally:
        stop(proc)


def run(rounds: int) -> dict[str, Any]:
    from playwright.sync_api import sync_playwright

    require_private_netns("startup")
    configure_dds(40)
    times: dict[str, list[tuple[float, float]]] = {"dashboard": [], "baseline": []}
    with sync_playwright() as pw:
        browser = launch_browser(pw)
        for k in range(rounds):
            for kind in ("baseline", "dashboard"):
                ready, shown = one_start(browser, kind)
                times[kind].append((ready, shown))
                print(f"round {k + 1} {kind:9s}: ready line {ready:.2f} s, page {shown:.2f} s")
        browser.close()
    dash, base = times["dashboard"], times["baseline"]
    dr, dp = summary([r for r, _ in dash]), summary([p for _, p in dash])
    br, bp = summary([r for r, _ in base]), summary([p for _, p in base])
    return {
        "rounds": rounds,
        "startup_ready_s": dr["p50"],
        "startup_page_s": dp["p50"],
        "startup_baseline_ready_s": br["p50"],
        "startup_baseline_page_s": bp["p50"],
        "startup_ratio": ratio(dp["p50"], bp["p50"]),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench startup")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    f = run(args.rounds)
    print(
        f"serve -> page ready (p50): dashboard {f['startup_page_s']:.2f} s "
        f"(ready line {f['startup_ready_s']:.2f} s), bare viser+rclpy app "
        f"{f['startup_baseline_page_s']:.2f} s -> ratio {f['startup_ratio']:.2f}x"
    )
    print(json.dumps(rounded(f), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
