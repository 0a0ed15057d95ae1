"""Benchmark: a dashboard left running with a class's worth of work does not wear out.

One ``ros2-classroom serve`` with five headless Chromium pages (one browser
process, five contexts) on different tools, the camera and arm pipeline
(launch group ``camera_to_arm``), the MuJoCo world (``sim_world``) and a
learner's node (the Exercise tab's **Run my node** on the reference solution
of ``multiply_service``), all started from the first page as a learner
starts them. Then, for ``--minutes`` (3 for ``make bench``, 30 for the real
soak), psutil samples the dashboard process every ``--every`` seconds:
resident memory, threads, open file descriptors.

Figures (summary JSON keys):

- ``soak_rss_growth_percent``: RSS at the end against RSS after the warm-up
  (the first fifth of the run, at most 5 minutes: the 30-minute form
  compares with minute 5); aim <= 10;
- ``soak_threads_growth``, ``soak_fds_growth``: the same for threads and
  file descriptors (aim: flat, at most 2);
- ``soak_log_errors``: ERROR/CRITICAL lines and tracebacks in the
  dashboard's log over the whole run (aim 0);
- ``soak_click_p95_ms``: at the end, each tool tab is opened as a learner
  opens it (its group's tab, then its own, ``open_tool``'s two clicks),
  twice over, timed inside the page from the first click to the frame that
  shows the tool's panel; p95 of all (aim < 150 ms).

A figure that cannot be measured (the dashboard died, a tab never showed)
is a ``FAILED:`` line and NaN, and the benchmark exits 1.

The stage is the first lesson's (the live graph), so the pages do not draw the 3D
scene behind it; ``--stage "3D scene"`` puts the world on every page's stage (the
stage is the dashboard's, shared by its pages), the hardest case for the clicks.

Run: ``.venv/bin/python tests/run.py --bench soak [--minutes M] [--every S] [--stage S]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import shutil
import sys
import time
from pathlib import Path
from typing import Any

from bench._common import (
    LOGS,
    configure_dds,
    free_port,
    launch_browser,
    open_dashboard,
    open_tool,
    percentile,
    require_private_netns,
    rounded,
    spawn,
    stop,
    wait_for_text,
)

GROUP = "camera_to_arm"
GROUP_MODULES = ("camera_publisher", "coordinate_transform", "robotic_arm")
WORLD = "sim_world"
SLUG = "multiply_service"
WANTED = (*(f"nodes.{m}" for m in GROUP_MODULES), f"nodes.{WORLD}", f"{SLUG}.py")
PAGES = 5
# Where each page sits while the soak runs: the first drives, the others watch.
PAGE_TOOLS = ("Nodes", "3D view", "Graph", "Topics", "Logs")
WARMUP_MAX_SEC = 300.0
CLICK_AIM_MS = 150.0
CLICK_PASSES = 2
ERROR_LINE = re.compile(r"^\S+ \S+ (ERROR|CRITICAL) ", re.MULTILINE)

# Open a tool as open_tool does (its group's tab, then its own), inside the page:
# ms from the first click to the frame that shows the tool's panel; < 0 if it never did.
OPEN_TOOL_JS = """
async ([group, name]) => {
  const frame = () => new Promise((r) => requestAnimationFrame(() => r()));
  const visible = (el) => !!el && el.getClientRects().length > 0;
  const tab = (label) => [...document.querySelectorAll('[role=tab]')]
    .find((t) => t.textContent.trim() === label && visible(t));
  // Shown: selected, its panel on screen, and built (a tool's first opening shows
  // "Opening <name>…" until the dashboard has built it: app/dashboard.py).
  const shown = (t, built = false) => {
    if (!t || t.getAttribute('aria-selected') !== 'true') return false;
    const id = t.getAttribute('aria-controls');
    if (!id) return true;
    const panel = document.getElementById(id);
    return !!panel && visible(panel) &&
      !(built && panel.textContent.includes(`Opening ${name}…`));
  };
  const until = (pred, ms) => new Promise((resolve) => {
    if (pred()) return resolve(true);
    const observer = new MutationObserver(() => {
      if (pred()) { observer.disconnect(); clearTimeout(timer); resolve(true); }
    });
    const timer = setTimeout(() => { observer.disconnect(); resolve(pred()); }, ms);
    observer.observe(document.body, {subtree: true, childList: true, attributes: true});
  });
  // The dock's tabs answer the pointer, not a bare click(): send what a mouse sends.
  const press = (el) => {
    const o = {bubbles: true, cancelable: true, view: window, button: 0, isPrimary: true};
    el.dispatchEvent(new PointerEvent('pointerdown', o));
    el.dispatchEvent(new MouseEvent('mousedown', o));
    el.dispatchEvent(new PointerEvent('pointerup', o));
    el.dispatchEvent(new MouseEvent('mouseup', o));
    el.click();
  };
  const t0 = performance.now();
  let g = null, t = null;
  if (group) {
    if (!await until(() => (g = tab(group)), 5000)) return -1;
    press(g);
    if (!await until(() => shown(g), 5000)) return -2;
  }
  if (!await until(() => (t = tab(name)), 5000)) return -3;
  press(t);
  if (!await until(() => shown(t, true), 5000)) return -4;
  await frame();
  return performance.now() - t0;
}
"""


def start_dashboard(code: str) -> tuple[Any, str]:
    """``serve`` with a fresh progress folder that holds the learner's code already."""
    from app.exercises.workspace import write_atomically

    progress = LOGS / "bench-soak-progress"
    scratch = LOGS / "bench-soak-scratch"
    for folder in (progress, scratch, LOGS / "bench-soak-bags"):
        shutil.rmtree(folder, ignore_errors=True)
    write_atomically(progress / "default.code" / f"{SLUG}.py", code)  # Workspace._path
    port = free_port()
    proc, log = spawn(
        [sys.executable, "-m", "app", "serve", "--port", str(port)]
        + ["--progress-dir", str(progress), "--scratch-dir", str(scratch)],
        "bench-soak-dashboard.log",
    )
    wait_for_text(proc, log, "is ready", 90.0)
    return proc, f"http://127.0.0.1:{port}"


def children_running(pid: int, markers: tuple[str, ...]) -> list[str]:
    """Which of ``markers`` (module or script names) a live child of ``pid`` runs."""
    import psutil

    found = set()
    for child in psutil.Process(pid).children(recursive=True):
        try:
            if child.status() == psutil.STATUS_ZOMBIE:
                continue
            line = " ".join(child.cmdline())
        except psutil.Error:
            continue
        found.update(m for m in markers if m in line)
    return sorted(found)


def choose(page: Any, label: str, option: str | re.Pattern[str]) -> None:
    page.get_by_label(label, exact=True).filter(visible=True).first.click()
    page.get_by_role("option", name=option, exact=True).click()


def start_everything(page: Any, pid: int) -> None:
    """From the first page, as a learner: the launch group, the world, the learner's node."""
    from app.exercises.model import load_exercises

    exercise = load_exercises().get(SLUG)
    # The world last: once five pages draw it in software WebGL, each click waits.
    open_tool(page, "Exercise")
    choose(page, "Exercise", re.compile(rf"^{exercise.unit:02d} · {re.escape(exercise.title)}"))
    page.get_by_role("button", name="Run my node", exact=True).click()
    open_tool(page, "Nodes")
    choose(page, "Launch group", GROUP)
    page.get_by_role("button", name="Start group", exact=True).click()
    choose(page, "Catalog node", WORLD)
    page.get_by_role("button", name="Start", exact=True).click()
    deadline = time.monotonic() + 60
    while (running := children_running(pid, WANTED)) != sorted(WANTED):
        if time.monotonic() > deadline:
            missing = sorted(set(WANTED) - set(running))
            raise SystemExit(f"FAILED: not running after 60 s: {', '.join(missing)}")
        time.sleep(0.5)


def sample_process(pid: int) -> dict[str, float]:
    import psutil

    proc = psutil.Process(pid)
    return {
        "t": time.monotonic(),
        "rss_mb": proc.memory_info().rss / 2**20,
        "threads": float(proc.num_threads()),
        "fds": float(proc.num_fds()),
    }


def log_errors(log: Path) -> tuple[int, list[str]]:
    """ERROR/CRITICAL lines and tracebacks in the log; the first few of them."""
    text = log.read_text(errors="replace")
    lines = [m.group(0) for m in ERROR_LINE.finditer(text)]
    tracebacks = text.count("Traceback (most recent call last)")
    shown = [line.strip() for line in text.splitlines() if ERROR_LINE.match(line)][:5]
    return len(lines) + tracebacks, shown


def time_clicks(page: Any) -> tuple[list[tuple[str, float]], list[str]]:
    """Each tool opened as a learner opens it, CLICK_PASSES times; ((tool, ms), failures)."""
    from app.ui import GROUP_OF, TAB_NAMES

    times, failures = [], []
    for _ in range(CLICK_PASSES):
        for name in TAB_NAMES:
            took = page.evaluate(OPEN_TOOL_JS, [GROUP_OF.get(name), name])
            if took < 0:
                failures.append(f"{name} (step {-took})")
            else:
                times.append((name, float(took)))
            time.sleep(0.3)  # a learner reads before the next click
    return times, failures


def at_or_after(samples: list[dict[str, float]], t: float) -> dict[str, float]:
    return next((s for s in samples if s["t"] >= t), samples[-1])


def run(minutes: float, every: float, stage: str = "") -> dict[str, Any]:
    from playwright.sync_api import sync_playwright

    from app.exercises.model import load_exercises

    require_private_netns("soak")
    configure_dds(70)
    code = load_exercises().get(SLUG).reference
    dashboard, url = start_dashboard(code)
    log = LOGS / "bench-soak-dashboard.log"
    errors: list[str] = []
    samples: list[dict[str, float]] = []
    clicks: list[tuple[str, float]] = []  # (tool, ms)
    click_failures: list[str] = ["not measured: the soak did not reach its end"]
    try:
        with sync_playwright() as pw:
            browser = launch_browser(pw)
            pages = [open_dashboard(browser, url) for _ in range(PAGES)]
            driver = pages[0]
            # Each page on its tool before the world starts drawing (software WebGL:
            # five pages drawing it make every click slow to set up).
            for page, tool in zip(pages, PAGE_TOOLS, strict=True):
                open_tool(page, tool)
            start_everything(driver, dashboard.pid)  # ends on the Nodes tab
            if stage:  # the stage is the dashboard's, so every page shows it
                choose(driver, "On stage", stage)
            duration = minutes * 60.0
            warmup = min(duration / 5.0, WARMUP_MAX_SEC)
            began = time.monotonic()
            print(
                f"soak: {minutes:g} min, {PAGES} pages, {GROUP} + {WORLD} + the learner's "
                f"{SLUG}; baseline after {warmup:.0f} s",
                flush=True,
            )
            while time.monotonic() - began < duration:
                if dashboard.poll() is not None:
                    errors.append(f"the dashboard exited ({dashboard.returncode}) mid-soak")
                    break
                samples.append(sample_process(dashboard.pid))
                if len(samples) % max(1, int(60 / every)) == 1:
                    s = samples[-1]
                    print(
                        f"  t={s['t'] - began:5.0f} s: RSS {s['rss_mb']:.1f} MB, "
                        f"{s['threads']:.0f} threads, {s['fds']:.0f} fds",
                        flush=True,
                    )
                time.sleep(every)  # the pages run on their own meanwhile
            if dashboard.poll() is None:
                running = children_running(dashboard.pid, WANTED)
                if running != sorted(WANTED):
                    missing = ", ".join(sorted(set(WANTED) - set(running)))
                    errors.append(f"{missing} no longer running at the end")
                end = sample_process(dashboard.pid)
                clicks, click_failures = time_clicks(driver)
                errors += [f"tab never showed: {f}" for f in click_failures]
                samples.append(end)
            browser.close()
    finally:
        stop(dashboard)
    found, first_errors = log_errors(log)
    nan = math.nan
    ms = [took for _name, took in clicks]
    if len(samples) >= 2 and not any("exited" in e for e in errors):
        base = at_or_after(samples, samples[0]["t"] + warmup)
        end = samples[-1]
        rss = 100.0 * (end["rss_mb"] - base["rss_mb"]) / base["rss_mb"]
        threads, fds = end["threads"] - base["threads"], end["fds"] - base["fds"]
        start_rss = samples[0]["rss_mb"]
    else:
        errors.append("too few samples to compare")
        rss = threads = fds = start_rss = nan
        base = end = {"rss_mb": nan, "threads": nan, "fds": nan}
    return {
        "minutes": minutes,
        "samples": len(samples),
        "soak_rss_start_mb": start_rss,
        "soak_rss_warm_mb": base["rss_mb"],
        "soak_rss_end_mb": end["rss_mb"],
        "soak_rss_growth_percent": rss,
        "soak_threads_warm": base["threads"],
        "soak_threads_growth": threads,
        "soak_fds_warm": base["fds"],
        "soak_fds_growth": fds,
        "soak_log_errors": found,
        "soak_click_p50_ms": percentile(ms, 50) if not click_failures else nan,
        "soak_click_p95_ms": percentile(ms, 95) if not click_failures else nan,
        "soak_click_max_ms": max(ms) if ms else nan,
        "soak_clicks": len(clicks),
        # The slowest opens, to say which tool holds the figure up.
        "slowest_clicks": [
            f"{name} {took:.0f} ms" for name, took in sorted(clicks, key=lambda c: -c[1])[:4]
        ],
        "errors": errors,
        "log_error_lines": first_errors,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench soak")
    parser.add_argument("--minutes", type=float, default=3.0, help="3 for make bench, 30 to soak")
    parser.add_argument("--every", type=float, default=5.0, help="seconds between samples")
    parser.add_argument(
        "--stage",
        default="",
        help="put this on stage, e.g. '3D scene' (default: the first lesson's own stage)",
    )
    args = parser.parse_args(argv)
    f = run(args.minutes, args.every, args.stage)
    for error in f["errors"]:
        print(f"FAILED: {error}")
    aims = {
        "rss": f["soak_rss_growth_percent"] <= 10.0,
        "threads": f["soak_threads_growth"] <= 2,
        "fds": f["soak_fds_growth"] <= 2,
        "log": f["soak_log_errors"] == 0,
        "click": f["soak_click_p95_ms"] < CLICK_AIM_MS,
    }
    print(
        f"RSS: {f['soak_rss_start_mb']:.1f} MB at start, {f['soak_rss_warm_mb']:.1f} MB after "
        f"the warm-up, {f['soak_rss_end_mb']:.1f} MB at the end -> "
        f"{f['soak_rss_growth_percent']:+.1f} % (aim <= 10 %)"
    )
    print(
        f"threads {f['soak_threads_warm']:.0f} -> {f['soak_threads_growth']:+.0f}, "
        f"file descriptors {f['soak_fds_warm']:.0f} -> {f['soak_fds_growth']:+.0f} "
        "(aim: flat, <= 2)"
    )
    print(f"errors and tracebacks in the dashboard's log: {f['soak_log_errors']} (aim 0)")
    for line in f["log_error_lines"]:
        print(f"  {line[:160]}")
    print(
        f"open a tool at the end ({f['soak_clicks']} clicks): p50 {f['soak_click_p50_ms']:.0f} ms, "
        f"p95 {f['soak_click_p95_ms']:.0f} ms, max {f['soak_click_max_ms']:.0f} ms "
        f"(aim p95 < 150); slowest: {', '.join(f.pop('slowest_clicks')) or 'none'}"
    )
    f["aim_met"] = bool(all(aims.values()))
    f.pop("log_error_lines")
    print(json.dumps(rounded(f, 2), sort_keys=True))
    return 1 if f["errors"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
