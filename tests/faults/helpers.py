"""Shared by the fault and load tests: what the dashboard process is doing, and figures."""

from __future__ import annotations

import fcntl
import json
import time

import psutil

from app import PROJECT_ROOT
from tests.wire_client import WireClient

FIGURES = PROJECT_ROOT / "test-artifacts" / "reliability-figures.json"


def record(case: str, **figures: object) -> None:
    """Keep each case's measured figures in one JSON file (the issue asks for a table)."""
    FIGURES.parent.mkdir(exist_ok=True)
    with open(FIGURES.with_suffix(".lock"), "w") as lock:  # test workers write it at once
        fcntl.flock(lock, fcntl.LOCK_EX)
        data = json.loads(FIGURES.read_text()) if FIGURES.exists() else {}
        data[case] = figures
        FIGURES.write_text(json.dumps(data, indent=1, sort_keys=True))
    print(f"\n[{case}] {figures}")


def live_children(pid: int) -> list[psutil.Process]:
    """Live node processes (``python -m nodes.*``) under ``pid``."""
    out = []
    for child in psutil.Process(pid).children(recursive=True):
        try:
            if child.status() != psutil.STATUS_ZOMBIE and any(
                arg.startswith("nodes.") for arg in child.cmdline()
            ):
                out.append(child)
        except psutil.NoSuchProcess:
            pass
    return out


def rss_mb(pid: int) -> float:
    return psutil.Process(pid).memory_info().rss / 2**20


def graph_nodes(client: WireClient) -> list[str]:
    return client.graph_nodes()


def choose(client: WireClient, label: str, value: str) -> None:
    uuid = client.find(label, "GuiDropdownMessage")
    assert uuid, label
    client.set_value(uuid, value)


def timed(fn) -> float:
    started = time.monotonic()
    fn()
    return time.monotonic() - started


def overview(client: WireClient) -> str:
    """The Nodes panel's table of every catalog node and its state."""
    with client.lock:
        return next(
            (str(p["_markdown"]) for p in client.gui.values()
             if str(p.get("_markdown", "")).startswith("| node | state |")),
            "",
        )  # fmt: skip


def all_quiet(client: WireClient, pid: int) -> bool:
    """No node process alive, and the dashboard says none is active."""
    table = overview(client)
    busy = any(word in table for word in ("starting", "running", "stopping"))
    return bool(table) and not busy and not live_children(pid)
