"""Ctrl+C and SIGTERM as a ``threading.Event``, without the deadlock of setting it in a handler.

Python runs a signal handler in the main thread between two bytecodes, which
can be while that thread is inside ``Event.wait()`` holding the event's own
lock. A handler that calls ``event.set()`` then waits for that lock for ever:
the process ignores every later Ctrl+C and never stops what it started (a CI
run's classroom hung like this, its three dashboards still running 45 minutes
later). So the handler here only writes a byte to a pipe, which takes no
Python lock, and a small thread of ours reads it and sets the event.
"""

from __future__ import annotations

import ctypes
import os
import signal
import threading
from collections.abc import Callable, Iterable

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
_PR_SET_PDEATHSIG = 1
_libc = ctypes.CDLL(None, use_errno=True)


def die_with(parent: int, death_signal: int = signal.SIGTERM) -> Callable[[], None]:
    """What a child runs between fork and exec (``preexec_fn``): die with ``parent``.

    ``death_signal`` is what the kernel sends the child when ``parent`` dies:
    SIGTERM lets our own programs end cleanly (a node leaves the graph, a bag is
    closed). A learner's program gets SIGKILL: code we did not write may catch
    SIGTERM, block in it, or take its time ending, and nobody is left to follow
    up (a CI rehearsal: a learner's service outlived its SIGKILLed dashboard).

    A fork keeps its parent's signal handlers until it execs, and ours (above)
    turn SIGTERM into a byte on a pipe: a parent that died in that moment sent
    its parent-death SIGTERM to a handler that did nothing, and the child ran
    on for ever (CI: a learner's program outlived a SIGKILLed dashboard). So
    the stop signals go back to their default first. The parent-death signal
    only comes for a death after it is set: a parent that died between the fork
    and here left this child to another, so it ends at once.
    """

    def set_parent_death_signal() -> None:
        for number in STOP_SIGNALS:
            signal.signal(number, signal.SIG_DFL)
        _libc.prctl(_PR_SET_PDEATHSIG, death_signal, 0, 0, 0)
        if os.getppid() != parent:
            os._exit(1)

    return set_parent_death_signal


def set_on_signals(
    event: threading.Event, signals: Iterable[signal.Signals] = STOP_SIGNALS
) -> Callable[[], None]:
    """Make each of ``signals`` set ``event``; call the result to put the old handlers back.

    Call from the main thread (only it may install handlers).
    """
    read_fd, write_fd = os.pipe()
    os.set_blocking(write_fd, False)  # a handler must never block; a full pipe has said it

    def on_signal(_signum: int, _frame: object) -> None:
        try:
            os.write(write_fd, b"!")
        except OSError:
            pass  # full (the stop is already on its way) or closed (handlers being restored)

    def relay() -> None:
        while os.read(read_fd, 64):
            event.set()
        os.close(read_fd)

    relay_thread = threading.Thread(target=relay, name="stop-signals", daemon=True)
    relay_thread.start()
    previous = {sig: signal.signal(sig, on_signal) for sig in signals}

    def restore() -> None:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        os.close(write_fd)  # the relay reads end-of-file and ends
        relay_thread.join(timeout=1.0)

    return restore
