"""Nothing we start outlives its run: a mark in the environment, and a check at the end.

``make bench`` and ``make test`` put one mark in their environment at the
start; every process they start, and everything those start, inherits it,
even a grandchild in its own session or one orphaned when its parent died (a
benchmark child hung in its teardown, a node a test forgot). At the end,
``leftovers`` finds the processes that still carry the mark, and
``end_leftovers`` kills them and says who they were, so the run can fail
instead of leaving them to load every later measurement.
"""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Callable
from pathlib import Path

MARK = "CLASSROOM_RUN_MARK"


def mark_this_run(kind: str) -> str:
    """Give this process (and so all its descendants) a mark of its own; returns it."""
    mark = f"{kind}-{os.getpid()}-{time.time_ns()}"
    os.environ[MARK] = mark
    return mark


def _ancestors() -> set[int]:
    """This process and its parents: they carry the mark and are not leftovers."""
    found, pid = set(), os.getpid()
    while pid > 1 and pid not in found:
        found.add(pid)
        try:
            stat = Path(f"/proc/{pid}/stat").read_text()
            pid = int(stat.rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            break
    return found


def leftovers(mark: str) -> list[tuple[int, str]]:
    """(pid, command line) of every live process that carries ``mark``, but us."""
    needle = f"{MARK}={mark}".encode()
    mine = _ancestors()
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) in mine:
            continue
        try:
            if needle not in (entry / "environ").read_bytes().split(b"\0"):
                continue
            if (entry / "stat").read_text().rsplit(")", 1)[1].split()[0] == "Z":
                continue  # already dead, waiting for its parent to reap it
            cmd = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except (OSError, IndexError):
            continue  # gone meanwhile, or not ours to read
        found.append((int(entry.name), cmd.strip()[:160]))
    return found


def end_leftovers(mark: str, grace: float = 5.0) -> list[str]:
    """Wait up to ``grace`` s for marked processes to end, kill the rest; describe them."""
    return end_found(lambda: leftovers(mark), grace)


def end_found(find: Callable[[], list[tuple[int, str]]], grace: float = 5.0) -> list[str]:
    """Wait up to ``grace`` s until ``find()`` finds nothing, kill what it still finds."""
    deadline = time.monotonic() + grace
    while (left := find()) and time.monotonic() < deadline:
        time.sleep(0.2)
    described = []
    for pid, cmd in left:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            continue
        described.append(f"pid {pid}: {cmd}")
    return described
