"""Benchmark: the bytes the dashboard sends one browser per second, in three situations.

The real dashboard (``ros2-classroom serve``) and one headless Chromium page
(1400x900), driven as a learner drives it:

- **idle** (``ws_idle_kBps``): the page open on the lesson it starts on,
  nothing running, nobody clicking;
- **graph** (``ws_graph_kBps``): the catalog's ``talker`` and ``listener``
  started from the Nodes tool, the live graph on stage, its message dots
  moving;
- **scene** (``ws_scene_kBps``): talker and listener stopped, lesson 15's
  pipeline started (launch group ``camera_to_arm``: camera_publisher ->
  coordinate_transform -> robotic_arm), lesson 15 open, the 3D view tool
  open and the 3D scene on stage, the arm drawn and moving. Aim: at most
  100 kB/s (issue 43).

Counted on the server's sockets, not estimated: ``ss -tin`` (iproute2, the
kernel's ``tcp_info`` through netlink) lists every established TCP socket
of the dashboard's port with ``bytes_acked``, the bytes of payload the
browser's end has acknowledged (websocket frames with their headers, and
any HTTP answer on the same port; retransmissions are not counted twice).
The bench runs in its own network namespace (``tests/run.py``), so that
port's sockets are this page's and nobody else's. Sockets are read every
``SAMPLE_SEC`` over the window, so one that opens or closes inside it
counts too (an opening one from zero, a closing one up to its last read).
Why not the browser's DevTools (``Network.webSocketFrameReceived``): viser
speaks over its websocket from a web worker, which a page's CDP session does
not see without attaching to the worker, and it would count what the browser
decoded, not what the server put on the wire. kB is 1000 bytes.

Each window is ``--seconds`` long (20 by default) after a warm-up of
``--warmup`` seconds in the same situation. A figure that cannot be measured
is NaN with a ``FAILED:`` line, and the benchmark exits 1.

Run: ``.venv/bin/python tests/run.py --bench ws_traffic [--seconds S]
[--warmup S]``. The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from bench._common import (
    configure_dds,
    launch_browser,
    open_dashboard,
    open_tool,
    require_private_netns,
    rounded,
    start_dashboard,
    stop,
)

SAMPLE_SEC = 0.25
SCENE_AIM_KBPS = 100.0
# What issue 43 saw when it tried (no aim for these two: they must not grow unseen).
SEEN_IN_ISSUE = {"idle": 0.0, "graph": 1.3, "scene": 69.0}
GRAPH_NODES = ("talker", "listener")
SCENE_GROUP = "camera_to_arm"
SCENE_LESSON = "15_frames_and_arm"
ARM_JOINT = "/base_link/arm/joint4"

BOXES_JS = "() => document.querySelectorAll('svg.stage-graph g.sg-vertex').length"
DOTS_JS = "() => document.querySelectorAll('svg.stage-graph circle.sg-dot').length"
# Where a scene node is in the world now; null until the page has it.
WHERE_JS = """(n) => {
  const o = window.__viserMutable && window.__viserMutable.nodeRefFromName[n];
  if (!o || !o.visible) return null;
  o.updateWorldMatrix(true, false);
  const e = o.matrixWorld.elements;
  return [e[12], e[13], e[14]];
}"""
MOVED_JS = f"""([n, old]) => {{
  const now = ({WHERE_JS})(n);
  return !!now && Math.hypot(now[0] - old[0], now[1] - old[1], now[2] - old[2]) > 0.005;
}}"""

# ----------------------------------------------------------------- pure helpers

_PEER = re.compile(r"^\s*\d+\s+\d+\s+(\S+)\s+(\S+)")
_ACKED = re.compile(r"\bbytes_acked:(\d+)")


def parse_ss(text: str) -> dict[str, int]:
    """``ss -tinH`` output -> {"local peer": bytes_acked} for each socket listed.

    Each socket is a line with its queues and addresses and an indented line
    of ``tcp_info`` (``bytes_acked:N`` is missing while it is zero).
    """
    out: dict[str, int] = {}
    key: str | None = None
    for line in text.splitlines():
        head = _PEER.match(line)
        if head and not line[:1].isspace():
            key = f"{head.group(1)} {head.group(2)}"
            out[key] = 0
            continue
        acked = _ACKED.search(line)
        if acked and key is not None:
            out[key] = int(acked.group(1))
    return out


def bytes_in_window(samples: Sequence[Mapping[str, int]]) -> int:
    """Bytes sent over a window from socket reads taken through it (the first at its start).

    A socket in the first read counts from its value there; one that appears
    later opened inside the window and counts from zero; one that is gone
    counts up to its last read. Counters only grow: the largest read is kept.
    """
    if not samples:
        return 0
    base = dict(samples[0])
    top: dict[str, int] = {}
    for reads in samples:
        for key, value in reads.items():
            top[key] = max(top.get(key, 0), value)
    return sum(max(0, value - base.get(key, 0)) for key, value in top.items())


def kilobytes_per_s(sent: int, seconds: float) -> float:
    """kB (1000 bytes) per second; NaN for a window of no length."""
    return sent / 1000.0 / seconds if seconds > 0 else math.nan


# ----------------------------------------------------------------- measuring


def socket_bytes(port: int) -> dict[str, int]:
    """bytes_acked of every established TCP socket whose local port is ``port``."""
    done = subprocess.run(
        ["ss", "-tinH", "state", "established", f"( sport = :{port} )"],
        capture_output=True,
        text=True,
        timeout=10,
        check=True,
    )
    return parse_ss(done.stdout)


def count_window(port: int, seconds: float) -> tuple[float, int]:
    """(kB/s the server sent on ``port``'s sockets over ``seconds``, sockets seen)."""
    samples = [socket_bytes(port)]
    t0 = time.monotonic()
    while (left := seconds - (time.monotonic() - t0)) > 0:
        time.sleep(min(SAMPLE_SEC, left))
        samples.append(socket_bytes(port))
    elapsed = time.monotonic() - t0
    seen = {key for reads in samples for key in reads}
    return kilobytes_per_s(bytes_in_window(samples), elapsed), len(seen)


# ----------------------------------------------------------------- the page


def choose(page: Any, label: str, option: str, timeout: float = 30.0) -> None:
    """Pick ``option`` in the dropdown ``label``; opened again if it is not listed yet."""
    dropdown = page.get_by_label(label, exact=True).filter(visible=True).first
    wanted = page.get_by_role("option", name=option, exact=True)
    deadline = time.monotonic() + timeout
    while True:
        dropdown.click()
        try:
            wanted.wait_for(timeout=1_500)
            wanted.click(timeout=10_000)
            return
        except Exception:
            if dropdown.input_value() == option:
                return
            page.keyboard.press("Escape")
            if time.monotonic() > deadline:
                raise SystemExit(f"option {option!r} never appeared in {label!r}") from None
            page.wait_for_timeout(500)


def shown(page: Any, text: str, timeout_ms: float = 30_000) -> None:
    page.get_by_text(text).filter(visible=True).first.wait_for(timeout=timeout_ms)


def catalog(page: Any, node: str, button: str) -> None:
    """Start or stop one catalog node from the Nodes tool, as a learner does."""
    open_tool(page, "Nodes")
    choose(page, "Catalog node", node)
    page.get_by_role("button", name=button, exact=True).click()
    if button == "Start":
        shown(page, f"Started {node}")


def to_graph(page: Any) -> None:
    """talker and listener running, the live graph on stage with its dots moving."""
    for node in GRAPH_NODES:
        catalog(page, node, "Start")
    choose(page, "On stage", "Live ROS graph")
    open_tool(page, "Lessons")  # the learner reads on while the graph animates
    page.wait_for_function(f"() => ({BOXES_JS})() >= 3", polling=200, timeout=60_000)
    page.wait_for_function(f"() => ({DOTS_JS})() > 0", polling=200, timeout=60_000)


def to_scene(page: Any) -> None:
    """Lesson 15's camera -> transform -> arm running, the 3D view showing the arm move."""
    from app.lessons.schema import LESSONS_DIR, load_lesson

    for node in GRAPH_NODES:
        catalog(page, node, "Stop")
    open_tool(page, "Nodes")
    choose(page, "Launch group", SCENE_GROUP)
    page.get_by_role("button", name="Start group", exact=True).click()
    shown(page, "Started group")
    lesson = load_lesson(LESSONS_DIR / SCENE_LESSON)
    open_tool(page, "Lessons")
    choose(page, "Lesson", f"{lesson.unit:02d} · {lesson.title}")
    open_tool(page, "3D view")
    choose(page, "On stage", "3D scene")
    shown(page, "gripper at", 60_000)
    page.wait_for_function(WHERE_JS, arg=ARM_JOINT, polling=200, timeout=60_000)
    start = page.evaluate(WHERE_JS, ARM_JOINT)
    page.wait_for_function(MOVED_JS, arg=[ARM_JOINT, start], polling=200, timeout=60_000)


def run(seconds: float, warmup: float) -> tuple[dict[str, Any], list[str]]:
    from playwright.sync_api import sync_playwright

    require_private_netns("ws_traffic")
    configure_dds(83)
    figures: dict[str, Any] = {"seconds": seconds, "warmup_s": warmup}
    figures["load_average_start"] = os.getloadavg()[0]  # others may share the cores
    failures: list[str] = []
    for name in SEEN_IN_ISSUE:
        figures[f"ws_{name}_kBps"] = math.nan
    dashboard, url = start_dashboard("bench-ws-traffic-dashboard.log")
    port = int(url.rsplit(":", 1)[1])
    try:
        with sync_playwright() as pw:
            browser = launch_browser(pw)
            try:
                page = open_dashboard(browser, url)
                steps: list[tuple[str, Callable[[Any], None]]] = [
                    ("idle", lambda _page: None),
                    ("graph", to_graph),
                    ("scene", to_scene),
                ]
                for name, get_there in steps:
                    try:
                        get_there(page)
                    except (Exception, SystemExit) as exc:  # this situation not reached
                        failures.append(f"{name}: not reached ({type(exc).__name__}: {exc})")
                        break  # the next situations start from this one
                    time.sleep(warmup)
                    rate, sockets = count_window(port, seconds)
                    figures[f"ws_{name}_kBps"] = rate
                    figures[f"ws_{name}_sockets"] = sockets
                    print(f"{name}: {rate:.3f} kB/s over {seconds:.0f} s, {sockets} socket(s)")
            finally:
                browser.close()
    finally:
        stop(dashboard)
    figures["load_average_end"] = os.getloadavg()[0]
    return figures, failures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench ws_traffic")
    parser.add_argument("--seconds", type=float, default=20.0, help="each window")
    parser.add_argument("--warmup", type=float, default=5.0, help="before each window")
    args = parser.parse_args(argv)
    figures, failures = run(args.seconds, args.warmup)
    scene = figures["ws_scene_kBps"]
    figures["ws_scene_aim_met"] = bool(not math.isnan(scene) and scene <= SCENE_AIM_KBPS)
    for name, seen in SEEN_IN_ISSUE.items():
        value = figures[f"ws_{name}_kBps"]
        aim = f"aim <= {SCENE_AIM_KBPS:.0f} kB/s" if name == "scene" else "no aim"
        print(
            f"bytes to one browser, {name}: {value:.3f} kB/s ({aim}; issue 43 saw about {seen:g})"
        )
    for name in SEEN_IN_ISSUE:
        if math.isnan(figures[f"ws_{name}_kBps"]) and not any(
            f.startswith(f"{name}:") for f in failures
        ):
            failures.append(f"{name}: not measured (an earlier situation failed)")
    for failure in failures:
        print(f"FAILED: {failure}", flush=True)
    print(json.dumps(rounded(figures, 3), sort_keys=True))
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
