"""Benchmark: the Exercise tab's Run and Check, in headless Chromium.

**Run.** The learner's code is the reference solution of ``multiply_service``
(node ``/multiplier``), written to the dashboard's progress folder before it
starts, and the editor is open on it (so Run's "save first" round trip to the
editor is part of the time, as for a learner). We click **Run my node** and
time until a plain rclpy observer in this process (the one of
``start_to_visible``, joined before the dashboard) sees ``/multiplier`` on the
graph. The baseline, in the same run and measured the same way, is the
equivalent catalog node: **Start** for ``add_two_ints_server`` in the Nodes
tab until ``/add_two_ints_server`` is on the graph. Both start a fresh Python
process through the same supervisor; the two alternate, and each node is
stopped and gone from the graph before the next click. Times run from the
click as the page sees it (a capture-phase listener's wall clock). Where the
time goes: the moment the process was spawned (its kernel start time) splits
each start into "dashboard work" and "process start + discovery".

**Check.** With the learner's node running, we click **Check my node** and
time inside the page, from the click to the DOM mutation that shows "All
checks pass" (after the old verdict has left the page).

Run: ``.venv/bin/python tests/run.py --bench exercise_run [--repeats N]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import time
from typing import Any

from app.ros.graph import live_and_ghost_nodes
from bench._common import (
    LOGS,
    configure_dds,
    free_port,
    launch_browser,
    open_dashboard,
    open_tool,
    ratio,
    require_private_netns,
    rounded,
    spawn,
    stop,
    summary,
    wait_for_text,
)
from bench.start_to_visible import OBSERVER_PERIOD_SEC, GraphObserver

SLUG = "multiply_service"
LEARNER_FQN = "/multiplier"
CATALOG = "add_two_ints_server"
CATALOG_FQN = "/add_two_ints_server"
TIMEOUT_SEC = 20.0
ALL_PASS = "All checks pass. Exercise done!"

# The last click's wall clock (ms), and for Check: the first DOM mutation
# after the click whose page text matches the armed pattern, once a mutation
# without it was seen (the previous verdict has gone).
PROBE_JS = r"""
window.__clickWall = null; window.__clickT = null; window.__doneT = null;
window.__re = null; window.__cleared = false;
window.__arm = (pattern) => {
  window.__clickT = null; window.__doneT = null; window.__cleared = false;
  window.__re = new RegExp(pattern);
};
document.addEventListener('click', () => {
  window.__clickWall = Date.now(); window.__clickT = performance.now();
}, true);
document.addEventListener('DOMContentLoaded', () => {
  new MutationObserver(() => {
    if (window.__re === null || window.__clickT === null || window.__doneT !== null) return;
    const shown = window.__re.test(document.body.textContent);
    if (!shown) window.__cleared = true;
    else if (window.__cleared) window.__doneT = performance.now();
  }).observe(document.body, {subtree: true, childList: true, characterData: true});
});
"""


class NodeWatch(GraphObserver):
    """start_to_visible's observer, watching several node names at once."""

    def __init__(self, name: str, fqns: tuple[str, ...]) -> None:
        self.fqns = fqns
        super().__init__(name)

    def _poll(self) -> None:
        present: dict[str, bool] = {}
        while not self._stop.wait(OBSERVER_PERIOD_SEC):
            live = live_and_ghost_nodes(self.node)[0]
            now = time.time()
            for fqn in self.fqns:
                seen = fqn in live
                if present.get(fqn) != seen:
                    present[fqn] = seen
                    with self._lock:
                        self.changes.append((now, fqn, seen))  # type: ignore[arg-type]

    def when(self, fqn: str, present: bool, after: float) -> float:
        deadline = time.monotonic() + TIMEOUT_SEC
        while time.monotonic() < deadline:
            with self._lock:
                hit = next(
                    (t for t, n, p in self.changes if n == fqn and p == present and t >= after),
                    None,
                )
            if hit is not None:
                return hit
            time.sleep(0.02)
        raise SystemExit(f"{fqn} {'never appeared' if present else 'never left'} in the graph")


def start_dashboard(code: str) -> tuple[subprocess.Popen, str]:
    """``serve`` with a fresh progress folder that already holds the learner's code."""
    from app.exercises.workspace import write_atomically

    progress = LOGS / "bench-exercise-progress"
    scratch = LOGS / "bench-exercise-scratch"
    for folder in (progress, scratch):
        shutil.rmtree(folder, ignore_errors=True)
    write_atomically(progress / "default.code" / f"{SLUG}.py", code)  # see Workspace._path
    port = free_port()
    proc, log = spawn(
        [sys.executable, "-m", "app", "serve", "--port", str(port)]
        + ["--progress-dir", str(progress), "--scratch-dir", str(scratch)],
        "bench-exercise-dashboard.log",
    )
    wait_for_text(proc, log, "is ready", 60.0)
    return proc, f"http://127.0.0.1:{port}"


def clock_offset() -> float:
    """psutil's process start times minus time.time() (a constant: boot time is whole seconds)."""
    import psutil

    t0 = time.time()
    child = subprocess.Popen(["sleep", "0.2"])
    t1 = time.time()
    offset = psutil.Process(child.pid).create_time() - (t0 + t1) / 2
    child.wait()
    return offset


def spawned_at(dashboard_pid: int, marker: str, offset: float) -> float | None:
    """When the dashboard's child whose command line names ``marker`` began (time.time())."""
    import psutil

    born = []
    for child in psutil.Process(dashboard_pid).children(recursive=True):
        try:
            if any(marker in arg for arg in child.cmdline()):
                born.append(child.create_time() - offset)
        except psutil.Error:
            continue
    return max(born, default=None)  # the newest: a stopped one may not be reaped yet


def enabled(page: Any, button: Any) -> None:
    page.wait_for_function(
        "b => !b.disabled", arg=button.element_handle(), polling=50, timeout=20_000
    )


def main_frame_click(page: Any, button: Any) -> tuple[float, float]:
    """Click; (wall clock before the click, wall clock of the click as the page saw it)."""
    enabled(page, button)
    page.evaluate("window.__clickWall = null")
    t0 = time.time()
    button.click()
    clicked = page.evaluate("window.__clickWall")
    return t0, (clicked / 1000.0 if clicked else t0)


def run(repeats: int, checks: int) -> dict[str, Any]:
    from playwright.sync_api import sync_playwright

    from app.exercises.model import load_exercises

    require_private_netns("exercise_run")
    configure_dds(30)
    exercise = load_exercises().get(SLUG)
    code = exercise.reference
    offset = clock_offset()
    watch = NodeWatch("bench_exercise_observer", (LEARNER_FQN, CATALOG_FQN))
    try:
        dashboard, url = start_dashboard(code)
    except BaseException:
        watch.close()
        raise
    starts: dict[str, list[float]] = {"exercise": [], "catalog": []}
    spawns: dict[str, list[float]] = {"exercise": [], "catalog": []}
    check_times: list[float] = []
    try:
        with sync_playwright() as pw:
            browser = launch_browser(pw)
            page = open_dashboard(browser, url, PROBE_JS)
            # The Exercise tab on multiply_service, its code open in the editor.
            open_tool(page, "Exercise")
            page.get_by_label("Exercise").click()
            label = re.compile(rf"^{exercise.unit:02d} · {re.escape(exercise.title)}")
            page.get_by_role("option", name=label).click()
            page.get_by_role("tab", name="Your code").click()
            editor = page.frame_locator(f"iframe[src*='slug={SLUG}']")
            editor.locator("#status").filter(has_text=re.compile("saved|connected")).wait_for()
            frame = page.frame(url=re.compile(rf"editor\.html\?slug={SLUG}"))
            if frame is None or frame.evaluate("window.classroomEditor.getValue()") != code:
                raise SystemExit("the editor does not show the reference solution")
            run_button = page.get_by_role("button", name="Run my node", exact=True)
            stop_mine = page.get_by_role("button", name="Stop (Ctrl+C)", exact=True)
            check_button = page.get_by_role("button", name="Check my node", exact=True)
            # The Nodes tab on the catalog node.
            open_tool(page, "Nodes")
            page.get_by_label("Catalog node").click()
            page.get_by_role("option", name=CATALOG, exact=True).click()
            start_button = page.get_by_role("button", name="Start", exact=True)
            stop_button = page.get_by_role("button", name="Stop", exact=True)
            page.wait_for_timeout(1500)  # the observer has discovered the dashboard by now

            ways = {
                "exercise": ("Exercise", run_button, stop_mine, LEARNER_FQN, f"{SLUG}.py"),
                "catalog": ("Nodes", start_button, stop_button, CATALOG_FQN, f"nodes.{CATALOG}"),
            }

            def start_and_stop(way: str) -> float:
                tab, start, halt, fqn, marker = ways[way]
                open_tool(page, tab)
                t0, clicked = main_frame_click(page, start)
                seen = watch.when(fqn, True, t0)
                born = spawned_at(dashboard.pid, marker, offset)
                starts[way].append(seen - clicked)
                if born is not None:
                    spawns[way].append(born - clicked)
                page.wait_for_timeout(800)  # let the node settle (services, parameters)
                t_stop, _ = main_frame_click(page, halt)
                watch.when(fqn, False, t_stop)
                page.wait_for_timeout(500)
                return seen - clicked

            for trial in range(repeats):
                order = ("catalog", "exercise") if trial % 2 == 0 else ("exercise", "catalog")
                took = {way: start_and_stop(way) for way in order}
                print(
                    f"repeat {trial + 1}: Run -> on graph {took['exercise'] * 1000:6.0f} ms, "
                    f"catalog Start -> on graph {took['catalog'] * 1000:6.0f} ms",
                    flush=True,
                )

            # Check: the learner's node runs; time Check until every result shows.
            open_tool(page, "Exercise")
            t0, _ = main_frame_click(page, run_button)
            watch.when(LEARNER_FQN, True, t0)
            page.wait_for_timeout(1000)
            for trial in range(checks):
                enabled(page, check_button)
                page.wait_for_timeout(300)
                page.evaluate("p => window.__arm(p)", r"All checks pass|\d+ of \d+ checks passed")
                check_button.click()
                page.wait_for_function("window.__doneT !== null", polling=50, timeout=30_000)
                took_ms = page.evaluate("window.__doneT - window.__clickT")
                shown = page.evaluate("document.body.textContent")
                if ALL_PASS not in shown or "random requests answered right" not in shown:
                    raise SystemExit("Check did not pass with the reference solution")
                check_times.append(took_ms / 1000.0)
                print(f"check {trial + 1}: click -> all results {took_ms:6.0f} ms", flush=True)
            t_stop, _ = main_frame_click(page, stop_mine)
            watch.when(LEARNER_FQN, False, t_stop)
            browser.close()
    finally:
        watch.close()
        stop(dashboard)
    ex, cat = summary(starts["exercise"]), summary(starts["catalog"])
    ex_spawn, cat_spawn = summary(spawns["exercise"]), summary(spawns["catalog"])
    chk = summary(check_times)
    return {
        "repeats": repeats,
        "checks": checks,
        "exercise_run_p50_ms": ex["p50"] * 1000,
        "exercise_run_p95_ms": ex["p95"] * 1000,
        "catalog_start_p50_ms": cat["p50"] * 1000,
        "catalog_start_p95_ms": cat["p95"] * 1000,
        "exercise_run_ratio": ratio(ex["p50"], cat["p50"]),
        "exercise_run_p95_ratio": ratio(ex["p95"], cat["p95"]),
        "exercise_run_extra_ms": (ex["p50"] - cat["p50"]) * 1000,
        "exercise_spawn_p50_ms": ex_spawn["p50"] * 1000,
        "catalog_spawn_p50_ms": cat_spawn["p50"] * 1000,
        "exercise_check_p50_s": chk["p50"],
        "exercise_check_p95_s": chk["p95"],
    }


def report(f: dict[str, Any]) -> None:
    print(
        f"Run click -> /multiplier on the graph: p50 {f['exercise_run_p50_ms']:.0f} ms, "
        f"p95 {f['exercise_run_p95_ms']:.0f} ms; catalog Start -> /add_two_ints_server: "
        f"p50 {f['catalog_start_p50_ms']:.0f} ms, p95 {f['catalog_start_p95_ms']:.0f} ms"
    )
    print(
        f"  ratio p50 {f['exercise_run_ratio']:.2f}x (aim <= 1.2), "
        f"p95 {f['exercise_run_p95_ratio']:.2f}x, +{f['exercise_run_extra_ms']:.0f} ms"
    )
    print(
        f"  click -> process spawned p50: Run {f['exercise_spawn_p50_ms']:.0f} ms, "
        f"catalog {f['catalog_spawn_p50_ms']:.0f} ms (the rest is Python, rclpy, discovery)"
    )
    print(
        f"Check click -> all results shown: p50 {f['exercise_check_p50_s']:.2f} s, "
        f"p95 {f['exercise_check_p95_s']:.2f} s (aim p50 < 3 s)"
    )
    f["aim_met_run"] = bool(f["exercise_run_ratio"] <= 1.2)
    f["aim_met_check"] = bool(f["exercise_check_p50_s"] < 3.0)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench exercise_run")
    parser.add_argument("--repeats", type=int, default=8)
    parser.add_argument("--checks", type=int, default=4)
    args = parser.parse_args(argv)
    figures = run(args.repeats, args.checks)
    report(figures)
    print(json.dumps(rounded(figures), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
