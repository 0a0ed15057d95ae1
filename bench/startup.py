"""Benchmark: ``ros2-classroom serve`` to the first page ready, against a bare viser + rclpy app.

Each round starts the process, waits for the line that gives the page's
address, then loads the page in headless Chromium until the GUI has rendered
whole (the dashboard's tabs, with no line left saying it is starting; the
baseline's one line of text). The bare app says its address once it is all
built; ``serve`` as soon as its web server listens, so the page loads while
it builds the rest (app/ui/opening.py), and a learner who opens the address
at once waits for the slower of the two, not their sum. The baseline is the
least such an app can be: ``rclpy.init``, one node, one ``viser.ViserServer``
with one markdown. Beside it, the same bare app written address first, as
``serve`` now is (``startup_ratio_against_address_first``, no aim): how much
of the gain any app could have had. Rounds alternate, so a load spike hits both alike.

Two dashboards are timed (issue 43): ``serve`` started cold, as ``make run``
does on a laptop (``startup_ratio``), and the same command forked from a
warm parent (app/warm_start.py) as the one-server set-ups (``classroom``,
the hub's local spawner) start each learner's (``startup_warm_ratio``). The
warm parent is started once before the rounds, as a classroom starts it
before its learners arrive; each round times one fork, from the request to
the page.

Run: ``.venv/bin/python tests/run.py --bench startup [--rounds N]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import threading
import time
from pathlib import Path
from typing import Any

from app.ui.opening import OPENING_WORDS
from bench._common import (
    LOGS,
    ROOT,
    configure_dds,
    dashboard_argv,
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

# How both bare apps end: they serve until stopped.
_SERVE_UNTIL_STOPPED = """
try:
    threading.Event().wait()
except KeyboardInterrupt:
    pass
finally:
    server.stop()
    rclpy.try_shutdown()
"""

BARE_APP = (
    """
import sys, threading
import rclpy, viser
from rclpy.node import Node
rclpy.init()
node = Node("bench_bare_app")
server = viser.ViserServer(host="127.0.0.1", port=int(sys.argv[1]), verbose=False)
server.gui.add_markdown("bare app")
print("bare app is ready", flush=True)
"""
    + _SERVE_UNTIL_STOPPED
)


# The same bare app written as `serve` now is: its web server and address first, then
# rclpy and its node while a browser loads the page. Not the baseline; timed
# beside it so the note can say how much of the dashboard's gain any app could have.
BARE_APP_ADDRESS_FIRST = (
    """
import sys, threading
import viser
server = viser.ViserServer(host="127.0.0.1", port=int(sys.argv[1]), verbose=False)
print("bare app is starting", flush=True)
import rclpy
from rclpy.node import Node
rclpy.init()
node = Node("bench_bare_app")
server.gui.add_markdown("bare app")
"""
    + _SERVE_UNTIL_STOPPED
)

KINDS = ("baseline", "dashboard", "warm", "baseline_address_first")


def _fork_warm(starter: Any, argv: list[str], log: Path) -> Any:
    """``argv`` as a fork of the warm parent, its output copied to ``log`` by a thread."""
    out = log.open("wb")  # emptied before the fork: never the last round's ready line
    try:
        child = starter.spawn(argv, starter.env, ROOT)
    except BaseException:
        out.close()
        raise
    assert child.stdout is not None

    def copy() -> None:
        with out:
            for raw in child.stdout:
                out.write(raw)
                out.flush()

    threading.Thread(target=copy, name="warm-output", daemon=True).start()
    return child


def one_start(browser: Any, kind: str, starter: Any) -> tuple[float, float]:
    """(seconds to the line giving the page's address, seconds to the page rendered whole),
    from the spawn."""
    port = free_port()
    log = LOGS / f"bench-startup-{kind}.log"
    t0 = time.monotonic()
    if kind == "baseline":
        proc, log = spawn([sys.executable, "-c", BARE_APP, str(port)], log.name)
    elif kind == "baseline_address_first":
        proc, log = spawn([sys.executable, "-c", BARE_APP_ADDRESS_FIRST, str(port)], log.name)
    elif kind == "dashboard":
        proc, log = spawn(dashboard_argv(port), log.name)
    else:
        proc = _fork_warm(starter, dashboard_argv(port), log)
    try:
        # The page is opened as soon as its address is said: the bare app says it once all
        # is built, `serve` as soon as its web server listens (app/ui/opening.py).
        said = "is ready" if kind == "baseline" else "is starting"
        ready = wait_for_text(proc, log, said, 60) - t0
        context = browser.new_context(viewport={"width": 1400, "height": 900})
        page = context.new_page()
        page.goto(f"http://127.0.0.1:{port}")
        if kind.startswith("baseline"):
            page.get_by_text("bare app").wait_for(timeout=60_000)
        else:  # the whole dashboard: its tabs, and no line saying it is still starting
            page.get_by_role("tab", name="Learn", exact=True).wait_for(timeout=60_000)
            page.get_by_text(OPENING_WORDS).wait_for(state="detached", timeout=60_000)
        shown = time.monotonic() - t0
        context.close()
        return ready, shown
    finally:
        stop(proc)


def run(rounds: int) -> dict[str, Any]:
    from playwright.sync_api import sync_playwright

    from app.warm_start import WarmStarter

    require_private_netns("startup")
    configure_dds(40)
    times: dict[str, list[tuple[float, float]]] = {kind: [] for kind in KINDS}
    # The environment every start gets (a fork's must equal the warm parent's).
    starter = WarmStarter({**os.environ, "PYTHONUNBUFFERED": "1"}, say=print)
    try:
        started = time.monotonic()
        starter.start()
        print(f"warm parent ready in {time.monotonic() - started:.2f} s (paid once, not timed)")
        with sync_playwright() as pw:
            browser = launch_browser(pw)
            for k in range(rounds):
                for kind in KINDS:
                    ready, shown = one_start(browser, kind, starter)
                    times[kind].append((ready, shown))
                    print(f"round {k + 1} {kind:9s}: address {ready:.2f} s, page {shown:.2f} s")
            browser.close()
    finally:
        starter.close()
    p50 = {
        kind: (summary([r for r, _ in got])["p50"], summary([p for _, p in got])["p50"])
        for kind, got in times.items()
    }
    return {
        "rounds": rounds,
        "startup_ready_s": p50["dashboard"][0],
        "startup_page_s": p50["dashboard"][1],
        "startup_baseline_ready_s": p50["baseline"][0],
        "startup_baseline_page_s": p50["baseline"][1],
        "startup_ratio": ratio(p50["dashboard"][1], p50["baseline"][1]),
        "startup_warm_ready_s": p50["warm"][0],
        "startup_warm_page_s": p50["warm"][1],
        "startup_warm_ratio": ratio(p50["warm"][1], p50["baseline"][1]),
        "startup_baseline_address_first_page_s": p50["baseline_address_first"][1],
        "startup_ratio_against_address_first": ratio(
            p50["dashboard"][1], p50["baseline_address_first"][1]
        ),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench startup")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    f = run(args.rounds)
    print(
        f"serve -> page ready (p50): dashboard {f['startup_page_s']:.2f} s "
        f"(address line {f['startup_ready_s']:.2f} s), bare viser+rclpy app "
        f"{f['startup_baseline_page_s']:.2f} s -> ratio {f['startup_ratio']:.2f}x; "
        f"forked warm {f['startup_warm_page_s']:.2f} s (address line "
        f"{f['startup_warm_ready_s']:.2f} s) -> ratio {f['startup_warm_ratio']:.2f}x; "
        f"the bare app with its address first {f['startup_baseline_address_first_page_s']:.2f} s "
        f"(cold serve against it {f['startup_ratio_against_address_first']:.2f}x)"
    )
    print(json.dumps(rounded(f), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
