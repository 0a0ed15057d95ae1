"""Benchmark: node start to visible (and stop to gone) in the dashboard's graph.

In headless Chromium we click **Start** for ``talker`` in the Nodes tab and
time how long until the Graph panel's update listing ``/talker`` reaches the
page; then **Stop** until the update without it. The baseline, in the same
run and from the same click, is plain rclpy observers in this process that
poll ``get_node_names_and_namespaces()`` every 10 ms: they show how long the
node itself takes to start (or leave) and be discovered, which no dashboard
can beat. There are two, one joined before the dashboard and one after, and
the earlier of them counts: which DDS participant hears of a new node first
depends on discovery order (a late match waits for Fast DDS's next heartbeat,
up to about 3 s), and the baseline should not lose that lottery.

Run: ``.venv/bin/python tests/run.py --bench start_to_visible [--trials N]``.
The last line printed is one JSON object (``stop_to_gone`` reports the stop
half of the same run).
"""

from __future__ import annotations

import argparse
import json
import threading
import time
from typing import Any

from app.graph import is_ghost
from bench._common import (
    configure_dds,
    launch_browser,
    open_dashboard,
    ratio,
    require_private_netns,
    rounded,
    start_dashboard,
    stop,
    summary,
)

NODE = "talker"
FQN = "/talker"
OBSERVER_PERIOD_SEC = 0.010
TIMEOUT_SEC = 20.0

# Time-stamp (wall clock, ms) every Graph panel update that reaches the page's
# main thread, with whether it lists /talker.
GRAPH_PROBE_JS = r"""
window.__graph = [];
const OrigWorker = window.Worker;
window.Worker = class extends OrigWorker {
  constructor(...args) {
    super(...args);
    this.addEventListener('message', (event) => {
      const data = event.data;
      if (!data || data.type !== 'message_batch') return;
      const t = performance.timeOrigin + performance.now();
      for (const m of data.messages) {
        if (m.type !== 'GuiUpdateMessage' || !m.updates) continue;
        for (const v of Object.values(m.updates)) {
          if (typeof v === 'string' && v.startsWith('**Nodes ('))
            window.__graph.push([t, /^- `\/talker`$/m.test(v)]);
        }
      }
    });
  }
};
"""


class GraphObserver:
    """The baseline: a bare rclpy node polling the graph every 10 ms in its own thread."""

    def __init__(self, name: str) -> None:
        import rclpy
        from rclpy.context import Context
        from rclpy.node import Node
        from rclpy.signals import SignalHandlerOptions

        self._rclpy = rclpy
        self.context = Context()
        rclpy.init(context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        self.node = Node(name, context=self.context)
        self._lock = threading.Lock()
        self.changes: list[tuple[float, bool]] = []  # (wall time s, present)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._poll, daemon=True)
        self._thread.start()

    def _poll(self) -> None:
        present = None
        while not self._stop.wait(OBSERVER_PERIOD_SEC):
            pairs = self.node.get_node_names_and_namespaces()
            # Same rule as the dashboard: a listed name with no endpoints is a ghost.
            seen = any(
                f"{ns.rstrip('/')}/{n}" == FQN and not is_ghost(self.node, n, ns) for n, ns in pairs
            )
            now = (seen, time.time())
            if now[0] != present:
                present = now[0]
                with self._lock:
                    self.changes.append((now[1], present))

    def first(self, present: bool, after: float) -> float | None:
        with self._lock:
            return next((t for t, p in self.changes if p == present and t >= after), None)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(1.0)
        self.node.destroy_node()
        self._rclpy.try_shutdown(context=self.context)


class Observers:
    """Several observers read as one: the earliest of them."""

    def __init__(self, *observers: GraphObserver) -> None:
        self.observers = observers

    def first(self, present: bool, after: float) -> float | None:
        seen = [o.first(present, after) for o in self.observers]
        if any(t is None for t in seen):
            return None
        return min(t for t in seen if t is not None)

    def close(self) -> None:
        for o in self.observers:
            o.close()


def page_first(page: Any, present: bool, after: float) -> float | None:
    for t_ms, shown in page.evaluate("window.__graph"):
        if shown == present and t_ms / 1000.0 >= after:
            return t_ms / 1000.0
    return None


def wait_both(page: Any, observer: Observers, present: bool, t0: float) -> tuple[float, float]:
    deadline = time.monotonic() + TIMEOUT_SEC
    while time.monotonic() < deadline:
        seen_obs = observer.first(present, t0)
        seen_page = page_first(page, present, t0)
        if seen_obs is not None and seen_page is not None:
            return seen_page - t0, seen_obs - t0
        time.sleep(0.05)
    what = "never appeared" if present else "never left"
    raise SystemExit(f"{FQN} {what} within {TIMEOUT_SEC} s")


def run(trials: int) -> dict[str, Any]:
    from playwright.sync_api import sync_playwright

    require_private_netns("start_to_visible")
    configure_dds(10)
    # Two plain observers, one joined before the dashboard and one after: which
    # participant hears a new node first depends on DDS discovery order (a
    # late match waits for the next heartbeat), so the baseline is the earlier.
    first = GraphObserver("bench_observer_first")
    try:
        dashboard, url = start_dashboard("bench-start-dashboard.log")
    except BaseException:
        first.close()
        raise
    observer = Observers(first, GraphObserver("bench_observer_last"))
    starts: dict[str, list[float]] = {"dashboard": [], "baseline": []}
    stops: dict[str, list[float]] = {"dashboard": [], "baseline": []}
    try:
        with sync_playwright() as pw:
            browser = launch_browser(pw)
            page = open_dashboard(browser, url, GRAPH_PROBE_JS)
            page.get_by_role("tab", name="Nodes").click()
            page.get_by_label("Catalog node").click()
            page.get_by_role("option", name=NODE, exact=True).click()
            start_button = page.get_by_role("button", name="Start", exact=True)
            stop_button = page.get_by_role("button", name="Stop", exact=True)
            page.wait_for_timeout(1500)  # the observer has discovered the dashboard by now
            for trial in range(trials):
                start_button.wait_for(state="visible")
                page.wait_for_function(
                    "b => !b.disabled", arg=start_button.element_handle(), polling=50
                )
                t0 = time.time()
                start_button.click()
                dash, base = wait_both(page, observer, True, t0)
                starts["dashboard"].append(dash)
                starts["baseline"].append(base)
                page.wait_for_timeout(800)  # let the node settle (topics, services)
                page.wait_for_function(
                    "b => !b.disabled", arg=stop_button.element_handle(), polling=50
                )
                t0 = time.time()
                stop_button.click()
                dash_gone, base_gone = wait_both(page, observer, False, t0)
                stops["dashboard"].append(dash_gone)
                stops["baseline"].append(base_gone)
                print(
                    f"trial {trial + 1}: start->visible dashboard {dash * 1000:6.0f} ms, "
                    f"observer {base * 1000:6.0f} ms | stop->gone dashboard "
                    f"{dash_gone * 1000:6.0f} ms, observer {base_gone * 1000:6.0f} ms",
                    flush=True,
                )
                page.wait_for_timeout(500)
            browser.close()
    finally:
        observer.close()
        stop(dashboard)
    ds, bs = summary(starts["dashboard"]), summary(starts["baseline"])
    dg, bg = summary(stops["dashboard"]), summary(stops["baseline"])
    return {
        "trials": trials,
        "start_dashboard_p50_ms": ds["p50"] * 1000,
        "start_dashboard_p95_ms": ds["p95"] * 1000,
        "start_baseline_p50_ms": bs["p50"] * 1000,
        "start_baseline_p95_ms": bs["p95"] * 1000,
        "start_ratio": ratio(ds["p50"], bs["p50"]),
        "start_extra_ms": (ds["p50"] - bs["p50"]) * 1000,
        "stop_to_gone_s": dg["p50"],
        "stop_to_gone_p95_s": dg["p95"],
        "stop_baseline_s": bg["p50"],
        "stop_ratio": ratio(dg["p50"], bg["p50"]),
    }


def report(figures: dict[str, Any]) -> None:
    print(
        f"start -> visible (p50): dashboard {figures['start_dashboard_p50_ms']:.0f} ms, "
        f"plain observer {figures['start_baseline_p50_ms']:.0f} ms -> "
        f"ratio {figures['start_ratio']:.2f}x, +{figures['start_extra_ms']:.0f} ms "
        "(aim <= 1.2x and < 150 ms)"
    )
    print(
        f"stop -> gone (p50): dashboard {figures['stop_to_gone_s']:.3f} s, "
        f"plain observer {figures['stop_baseline_s']:.3f} s (aim < 1 s)"
    )
    figures["aim_met_start"] = bool(
        figures["start_ratio"] <= 1.2 and figures["start_extra_ms"] < 150
    )
    figures["aim_met_stop"] = bool(figures["stop_to_gone_s"] < 1.0)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench start_to_visible")
    parser.add_argument("--trials", type=int, default=6)
    args = parser.parse_args(argv)
    figures = run(args.trials)
    report(figures)
    print(json.dumps(rounded(figures), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
