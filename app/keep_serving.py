"""``make run``'s keeper: start the dashboard again when its ROS guard ended it.

A dashboard whose DDS participant hangs is ended by its guard with SIGABRT
(app/ros/liveness.py); a native crash ends the same way. Either way the
learner's page should come back by itself, so this runs ``python -m app
ARGS...`` and runs it again after such an end. Any other end (Ctrl+C, an
error at start, SIGTERM) ends this too, with the dashboard's exit status.

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
import time

from app.stop_signals import die_with  # standard library only, too

RESTART_AFTER = -signal.SIGABRT  # Popen's returncode for "ended by SIGABRT"
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
    while True:
        started = time.monotonic()
        child = subprocess.Popen(
            [sys.executable, "-m", "app", *argv],
            preexec_fn=die_with(os.getpid()),  # the dashboard ends if this keeper is killed
        )
        code = child.wait()
        if code != RESTART_AFTER or interrupted:
            return code if code >= 0 else 128 - code
        quick_ends = quick_ends + 1 if time.monotonic() - started < CALM_SEC else 0
        if quick_ends >= 3:
            print(
                "== the dashboard ended three times in a row soon after starting: giving up",
                file=sys.stderr,
                flush=True,
            )
            return 128 - code
        print(
            "== the dashboard was ended by SIGABRT (its reason is above): starting it again",
            file=sys.stderr,
            flush=True,
        )


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
