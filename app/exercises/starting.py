"""Is a learner's program still starting? Its processes say, not the clock.

Importing rclpy, or ``ros2 launch`` starting the nodes of a launch file, keeps a
process runnable (``R``: running or waiting for a core) or in disk sleep
(``D``). A program that has started and waits for messages sleeps (``S``). So a
program whose processes were all asleep for a while has settled: if its node is
not on the graph by then, it never will be (a wrong name in ``Node()``). A
loaded machine makes starting slower, not different.
"""

from __future__ import annotations

import time

import psutil

WORKING = (psutil.STATUS_RUNNING, psutil.STATUS_DISK_SLEEP)
SETTLED_SEC = 1.0  # asleep this long (looked at each poll) counts as settled


class StartingWatch:
    """Looked at once a poll by the grader while it waits for the learner's node."""

    def __init__(self) -> None:
        self._last_busy = time.monotonic()

    def still_starting(self, pid: int | None) -> bool:
        """True while a process of the program (``pid`` and its descendants) worked in the
        last ``SETTLED_SEC``."""
        if pid is not None and _working(pid):
            self._last_busy = time.monotonic()
        return time.monotonic() - self._last_busy < SETTLED_SEC


def _working(pid: int) -> bool:
    try:
        root = psutil.Process(pid)
        family = [root, *root.children(recursive=True)]
    except psutil.Error:
        return False
    for process in family:
        try:
            if process.status() in WORKING:
                return True
        except psutil.Error:  # ended meanwhile
            continue
    return False
