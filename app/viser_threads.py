"""viser's message buffers made safe to push into from any thread, groups kept whole (issue 38).

viser 1.1.1's ``AsyncMessageBuffer.push`` (what every handle setter, ``add_*``
and ``remove`` ends in) calls ``message_event.set()`` on the calling thread,
besides scheduling the same call on the server's event loop.
``asyncio.Event.set`` walks the event's deque of waiters, which the loop
thread changes every time a client's window generator starts or stops waiting
(the broadcast buffer has one waiter per connected browser). Under load, a
handle set from our UI thread raised ``RuntimeError: deque mutated during
iteration`` (a stress run also met ``InvalidStateError``: a waiter cancelled
by the loop between ``done()`` and ``set_result``), and it completed the
waiters' futures off their loop.

``install()`` gives every buffer viser creates afterwards events whose
``set()`` runs on the buffer's own loop: directly when called there, handed
over with ``call_soon_threadsafe`` otherwise. Nothing in viser reads
``message_event.is_set()`` right after a push, and push already schedules a
set on the loop (``atomic_end`` does inside ``atomic()``), so deferring the
foreign thread's set loses no wake-up.
It also lifts the buffers' cap of 128 messages a window (``max_window_size``).
``atomic()`` only holds windows back while its block runs; the window after it
takes what waits, the group last, and stopped at 128, so a group queued behind
a burst of other updates (tools being built) reached the page in two frames:
the busy rehearsal ci150 drew a lesson's new step title with the last step's
buttons. Uncapped, what waits goes in one window, a page's first load too (one
batch for the page to apply instead of several). Upstream would need a window
that never ends inside an atomic group, and the window's last message chosen
under the buffer's lock together with the atomic count: read apart, as now, a
group that ends between the two reads is still sent cut (a race we have not
seen; tests/faults/test_viser_atomic.py).

Call it before constructing a ``ViserServer`` (``app.access.make_server``
does): the broadcast buffer is made while the server starts.
"""

from __future__ import annotations

import asyncio
import dataclasses
import functools
import sys
import threading
from typing import Any

from viser.infra._async_message_buffer import AsyncMessageBuffer

_MARK = "_classroom_loop_bound_events"
_LOCK = threading.Lock()
WINDOW_MESSAGES = sys.maxsize  # no cap: an atomic group is never cut at a window's end


class LoopBoundEvent(asyncio.Event):
    """An ``asyncio.Event`` whose ``set()`` always runs on ``loop``'s thread."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        super().__init__()
        self._owner_loop = loop

    def set(self) -> None:
        if asyncio._get_running_loop() is self._owner_loop:
            super().set()
            return
        if self.is_set():  # Event.set's own early exit: nothing to wake, no loop round-trip
            return
        try:
            self._owner_loop.call_soon_threadsafe(super().set)
        except RuntimeError:  # the loop is closed: no waiter is left to wake
            pass


def install() -> None:
    """Make every ``AsyncMessageBuffer`` created from now on use ``LoopBoundEvent``s
    and send what waits in one window.

    Idempotent. Fails loudly if a viser upgrade renamed the fields it replaces,
    so the workaround cannot silently stop applying.
    """
    with _LOCK:
        if getattr(AsyncMessageBuffer.__init__, _MARK, False):
            return
        names = {field.name for field in dataclasses.fields(AsyncMessageBuffer)}
        missing = {"event_loop", "message_event", "flush_event", "max_window_size"} - names
        if missing:
            raise RuntimeError(f"viser's AsyncMessageBuffer has no {sorted(missing)}")
        original = AsyncMessageBuffer.__init__

        @functools.wraps(original)
        def __init__(self: AsyncMessageBuffer, *args: Any, **kwargs: Any) -> None:
            original(self, *args, **kwargs)
            loop = self.event_loop
            if not isinstance(self.message_event, LoopBoundEvent):
                self.message_event = LoopBoundEvent(loop)
            if not isinstance(self.flush_event, LoopBoundEvent):
                self.flush_event = LoopBoundEvent(loop)
            self.max_window_size = WINDOW_MESSAGES

        setattr(__init__, _MARK, True)
        AsyncMessageBuffer.__init__ = __init__  # type: ignore[method-assign]
