"""What the dashboard benchmarks share: isolation check, processes, the browser, statistics.

Pure helpers (``percentile``, ``summary``, ``ratio``, ``rate_from_stamps``)
need no ROS and are unit-tested in tests/unit/test_bench_stats.py.
"""

from __future__ import annotations

import math
import os
import signal
import socket
import statistics
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
LOGS = ROOT / "test-artifacts"
CHROMIUM = "/usr/bin/chromium"
BROWSER_ARGS = ["--no-sandbox", "--disable-dev-shm-usage"]

# ----------------------------------------------------------------- statistics


def percentile(values: Sequence[float], q: float) -> float:
    """The q-th percentile (0-100) with linear interpolation; NaN for no values."""
    data = sorted(values)
    if not data:
        return math.nan
    if len(data) == 1:
        return float(data[0])
    pos = (len(data) - 1) * q / 100.0
    low = math.floor(pos)
    high = min(low + 1, len(data) - 1)
    return float(data[low] + (data[high] - data[low]) * (pos - low))


def summary(values: Sequence[float]) -> dict[str, float]:
    """p50, p95, mean and count of a sample (NaN figures for an empty one)."""
    return {
        "p50": percentile(values, 50),
        "p95": percentile(values, 95),
        "mean": statistics.fmean(values) if values else math.nan,
        "n": len(values),
    }


def ratio(value: float, baseline: float) -> float:
    """value / baseline, NaN when the baseline is zero or missing."""
    if not baseline or math.isnan(baseline) or math.isnan(value):
        return math.nan
    return value / baseline


def rate_from_stamps(stamps: Sequence[float]) -> float:
    """Messages per second as `ros2 topic hz` computes it: (n - 1) / (last - first)."""
    if len(stamps) < 2:
        return math.nan
    span = stamps[-1] - stamps[0]
    return (len(stamps) - 1) / span if span > 0 else math.nan


def rounded(figures: dict[str, Any], digits: int = 3) -> dict[str, Any]:
    """Floats rounded for printing; NaN becomes None so the JSON line stays valid JSON."""
    out: dict[str, Any] = {}
    for key, value in figures.items():
        if isinstance(value, float):
            out[key] = None if math.isnan(value) else round(value, digits)
        else:
            out[key] = value
    return out


# ----------------------------------------------------------------- environment


def require_private_netns(name: str) -> None:
    if [n for _, n in socket.if_nameindex()] != ["lo"]:
        raise SystemExit(
            f"run this inside the loopback-only namespace: "
            f".venv/bin/python tests/run.py --bench {name}"
        )


def configure_dds(offset: int) -> None:
    """A domain of its own for this benchmark run, loopback-only DDS profile."""
    from app.dds import configure_this_process

    configure_this_process(domain_id=(offset + os.getpid()) % 100 + 1, network=False)


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def wait_for_text(proc: subprocess.Popen, log: Path, text: str, timeout: float) -> float:
    """Poll a child's log for ``text``; returns the monotonic time it was first seen."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if text in log.read_text(errors="replace"):
            return time.monotonic()
        if proc.poll() is not None:
            raise SystemExit(f"{log.name}: exited early:\n{log.read_text(errors='replace')}")
        time.sleep(0.01)
    raise SystemExit(f"{log.name}: '{text}' not seen after {timeout:.0f} s")


def spawn(argv: list[str], log_name: str, **kwargs: Any) -> tuple[subprocess.Popen, Path]:
    LOGS.mkdir(exist_ok=True)
    log = LOGS / log_name
    proc = subprocess.Popen(
        argv,
        cwd=ROOT,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
        stdout=log.open("wb"),
        stderr=subprocess.STDOUT,
        start_new_session=True,
        **kwargs,
    )
    return proc, log


def dashboard_argv(port: int) -> list[str]:
    """``ros2-classroom serve`` on ``port``, its progress in the benchmarks' own folder."""
    progress = LOGS / "bench-progress"
    return [
        sys.executable,
        "-m",
        "app",
        "serve",
        "--port",
        str(port),
        "--progress-dir",
        str(progress),
    ]


def start_dashboard(log_name: str = "bench-dashboard.log") -> tuple[subprocess.Popen, str]:
    """``ros2-classroom serve`` as a child; returns it and its URL once it says it is ready."""
    port = free_port()
    proc, log = spawn(dashboard_argv(port), log_name)
    wait_for_text(proc, log, "is ready", 60.0)
    return proc, f"http://127.0.0.1:{port}"


def stop(proc: subprocess.Popen, timeout: float = 10.0) -> None:
    """SIGINT (Ctrl+C) first, as a learner would, then SIGKILL to its whole group.

    Children started by ``spawn`` lead their own process group: killing the
    group also ends what they started. What a child left after ending on its
    own is found by the run's mark (``bench._reaper``).
    """
    if proc.poll() is None:
        proc.send_signal(2)
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, 9)  # not yet reaped: the group id is still this child's
            proc.wait()


def launch_browser(playwright: Any) -> Any:
    return playwright.chromium.launch(executable_path=CHROMIUM, args=BROWSER_ARGS)


def open_dashboard(browser: Any, url: str, init_js: str | None = None) -> Any:
    """A fresh page on the dashboard, once viser's GUI has rendered."""
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    page = context.new_page()
    if init_js:
        page.add_init_script(init_js)
    page.goto(url)
    page.get_by_role("tab", name="Learn", exact=True).wait_for(timeout=30_000)
    return page


def open_tool(page: Any, name: str) -> None:
    """Open a dashboard tool as a learner does: its group's tab (Run, Inspect...), then its own
    (a tab outside the groups, such as the stage window's, directly)."""
    from playwright.sync_api import expect

    from app.ui import GROUP_OF

    group = GROUP_OF.get(name)
    for tab in (group, name) if group is not None else (name,):
        button = page.get_by_role("tab", name=tab, exact=True)
        button.click()
        # A click that did not select the tab says so here, not later as a "text not
        # visible" of whatever the test looks for next.
        expect(button, f"the {tab} tab is open").to_have_attribute("aria-selected", "true")


def machine() -> dict[str, Any]:
    import platform

    import psutil

    model = platform.processor() or "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    os_name = platform.platform()
    try:
        release = dict(
            line.split("=", 1) for line in Path("/etc/os-release").read_text().splitlines() if line
        )
        os_name = release.get("PRETTY_NAME", os_name).strip('"')
    except (OSError, ValueError):
        pass
    return {
        "cores": os.cpu_count(),
        "ram_gb": round(psutil.virtual_memory().total / 2**30, 1),
        "cpu_model": model,
        "python": platform.python_version(),
        "os": os_name,
    }


def sample(pids: dict[str, int], seconds: float) -> dict[str, dict[str, float]]:
    """CPU % of one core and memory (RSS, USS, PSS in MB) of each process over ``seconds``."""
    import psutil

    procs = {name: psutil.Process(pid) for name, pid in pids.items()}
    before = {name: p.cpu_times() for name, p in procs.items()}
    t0 = time.monotonic()
    time.sleep(seconds)
    elapsed = time.monotonic() - t0
    out = {}
    for name, proc in procs.items():
        after = proc.cpu_times()
        busy = (after.user - before[name].user) + (after.system - before[name].system)
        memory = proc.memory_full_info()
        out[name] = {
            "cpu_percent": 100.0 * busy / elapsed,
            "rss_mb": memory.rss / 2**20,
            "uss_mb": memory.uss / 2**20,
            "pss_mb": memory.pss / 2**20,
        }
    return out


TEARDOWN_SEC = 5  # a child that has written its figures gets this long to end


def end_bounded(node: Any, executor: Any) -> None:
    """Tear a benchmark child's ROS down in bounded time: entities, executor, context.

    A plain subscriber of a 1 kHz topic once spun at 95 % of a core for 15+
    minutes inside ``Node.destroy_node`` (the loop that destroys
    subscriptions, called after ``executor.shutdown()``), under load. The
    Python loop itself cannot spin (each pass removes one subscription): the
    time goes in the native reader teardown, with the GIL held, so no Python
    watchdog could run; the kernel's alarm (default action: end the process)
    bounds it instead. Entities are destroyed while the node is still known
    to its executor, then the executor is shut down: rclpy 7.1.6's
    ``Executor.shutdown`` does not wait for work in progress (it tests
    ``_is_shutdown`` right after setting it), so shutting it down first
    gains nothing.
    """
    import rclpy

    signal.signal(signal.SIGALRM, signal.SIG_DFL)
    signal.alarm(TEARDOWN_SEC)
    executor.remove_node(node)
    node.destroy_node()
    executor.shutdown(timeout_sec=1.0)
    rclpy.try_shutdown()
    signal.alarm(0)
