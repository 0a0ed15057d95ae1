"""``make run``'s keeper: start the dashboard again when its ROS guard ended it.

A dashboard whose DDS participant hangs is ended by its guard (app/ros/liveness.py);
a native crash ends it with SIGABRT. Either way the learner's page should come
back by itself, so this runs ``python -m app ARGS...`` and runs it again after
such an end (the rule: app/restart_rule.py). Any other end (Ctrl+C, an error at
start, SIGTERM) ends this too, with the dashboard's exit status.

Standard library only (app.stop_signals is too): this process must outlive
whatever its child does.
Ctrl+C in the terminal reaches the dashboard directly (one process group);
SIGTERM and SIGHUP sent here are passed on to it.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from app.restart_rule import GuardMark, ended_for_a_restart  # standard library only, too
from app.stop_signals import die_with  # standard library only, too

CALM_SEC = 30.0  # a dashboard that keeps dying sooner than this after its start is not restarted


def main(argv: list[str]) -> int:
    child: subprocess.Popen[bytes] | None = None
    interrupted = False

    def pass_on(number: int, _frame: object) -> None:
        nonlocal interrupted
        interrupted = True
        if child is not None and child.poll() is None and number != signal.SIGINT:
            child.send_signal(number)  # SIGINT already reached it from the terminal

    for number in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(number, pass_on)
    quick_ends = 0
    with tempfile.TemporaryDirectory(prefix="classroom-keeper-") as folder:
        mark = GuardMark(Path(folder), "dashboard")
        while True:
            mark.clear()
            started = time.monotonic()
            child = subprocess.Popen(
                [sys.executable, "-m", "app", *argv],
                env={**os.environ, **mark.env()},
                preexec_fn=die_with(os.getpid()),  # the dashboard ends if this keeper is killed
            )
            code = child.wait()
            status = code if code >= 0 else 128 - code  # a shell's status for a signal's end
            why = ended_for_a_restart(code, mark)
            if why is None or interrupted:
                return status
            quick_ends = quick_ends + 1 if time.monotonic() - started < CALM_SEC else 0
            if quick_ends >= 3:
                print(
                    "== the dashboard ended three times in a row soon after starting: giving up",
                    file=sys.stderr,
                    flush=True,
                )
                return status
            print(f"== the dashboard ended ({why}): starting it again", file=sys.stderr, flush=True)


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
