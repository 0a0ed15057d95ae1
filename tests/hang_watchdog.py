"""A test stuck in native code ends, as a failure, with every thread's stack in the log.

pytest-timeout (its signal method) raises in the main thread the next time that
thread runs Python. A thread blocked inside a C library never does: in ci119 a
lock-order deadlock inside Fast DDS 2.14.5 (eProsima/Fast-DDS#6502: the discovery
thread, holding the PDP mutex, waited for the event thread, which waited for the
PDP mutex) held the grader's ``create_subscription``, and the run hung until it
was killed 30 minutes later. faulthandler's watchdog is a C thread: once a test
has outlived its own timeout by ``MARGIN_SEC``, it writes every Python thread's
stack to the worker's timeline and ends the worker. xdist reports the test as
crashed and, with ``--max-worker-restart=0``, ends the run there; tests/run.py
prints the stacks after what failed (``hangs_in``). Stdlib only: tests/run.py
imports it.
"""

from __future__ import annotations

import faulthandler
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO

# Beyond the test's own timeout: pytest-timeout fires first, and a test that failed
# by it still tears its fixtures down (a dashboard's stop takes seconds).
MARGIN_SEC = 120.0
DUMP_START = "Timeout ("  # faulthandler's first line: "Timeout (0:05:00)!"
MAX_DUMP_LINES = 150  # a hang's stacks in the run's summary, not a whole log


def limit_for(own_timeout: float | None) -> float:
    """Seconds until the watchdog ends the process; 0 for a test without a timeout."""
    return own_timeout + MARGIN_SEC if own_timeout else 0.0


@contextmanager
def armed(seconds: float, log: IO[str]) -> Iterator[None]:
    """End this process, after writing every thread's stack to ``log``, if the block
    outlasts ``seconds`` (0: not at all)."""
    if seconds <= 0:
        yield
        return
    log.flush()
    faulthandler.dump_traceback_later(seconds, exit=True, file=log)
    try:
        yield
    finally:
        faulthandler.cancel_dump_traceback_later()


def hangs_in(text: str) -> list[str]:
    """The watchdog's dumps in a timeline's text, each cut at the next timeline line."""
    dumps: list[str] = []
    lines = text.splitlines()
    for at, line in enumerate(lines):
        if not line.startswith(DUMP_START):
            continue
        block = [line]
        for follow in lines[at + 1 :]:
            if follow[:2].isdigit() and follow[2:3] == ":":  # "HH:MM:SS ..." ends it
                break
            block.append(follow)
        dumps.append("\n".join(block[:MAX_DUMP_LINES]))
    return dumps


def new_text(path: Path, since: int) -> str:
    """What was appended to ``path`` after its first ``since`` bytes ('' if unreadable)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as log:
            log.seek(since)
            return log.read()
    except OSError:
        return ""
