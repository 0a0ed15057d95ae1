"""The UI thread's mailbox: intents from any thread, jobs that wait on ROS off that thread."""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

from app.ros.errors import Ros2Error

log = logging.getLogger(__name__)

T = TypeVar("T")
Intent = Callable[[], None]


def one_line(exc: BaseException) -> str:
    """An unexpected error as the learner sees it; the traceback goes to the log."""
    if isinstance(exc, Ros2Error):
        return str(exc)
    text = str(exc).splitlines()[0] if str(exc) else ""
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


class UiLoop:
    """Intents are applied in order by one thread (see the threading model in app.ui)."""

    def __init__(self) -> None:
        self._intents: queue.SimpleQueue[tuple[Intent, bool]] = queue.SimpleQueue()
        self._wake = threading.Event()
        self._lanes: dict[str, ThreadPoolExecutor] = {}
        self._lanes_lock = threading.Lock()
        self._closed = False

    # -- any thread ------------------------------------------------------------

    def post(self, intent: Intent, *, refresh: bool = True) -> None:
        """Ask the UI thread to run ``intent`` soon; returns at once.

        A ``refresh=False`` intent only reads state (e.g. the teacher's progress
        snapshot): it runs at the next pass without waking the loop or making
        every panel redraw.
        """
        self._intents.put((intent, refresh))
        if refresh:
            self._wake.set()

    def wake(self) -> None:
        """Wake the UI thread now: it looks at the graph and refreshes the panels."""
        self._wake.set()

    def callback(self, intent: Callable[..., None], *args: object) -> Callable[[object], None]:
        """A viser callback that posts ``intent(*args)`` when a browser changed the widget.

        viser also runs update callbacks, synchronously, when the server itself
        assigns a value (``event.client`` is None then): the UI thread made that
        change and already knows it, so no intent is posted for it. A dropdown value
        the dropdown does not offer never gets here (``app.viser_input``).
        """

        def on_event(event: object) -> None:
            if getattr(event, "client", True) is not None:
                self.post(lambda: intent(*args))

        return on_event

    def run_job(
        self,
        work: Callable[[], T],
        on_done: Callable[[T], None] | None = None,
        on_error: Callable[[str], None] | None = None,
        *,
        lane: str | None = None,
    ) -> None:
        """Run ``work`` on a worker thread; its outcome comes back as an intent.

        Jobs with the same ``lane`` run one at a time, in the order posted (two
        clicks on Start never overtake each other); lane-less jobs run at once.
        """

        def body() -> None:
            try:
                result = work()
            except Exception as exc:  # one line for the page, the traceback for the log
                if self._closed:  # the dashboard is stopping: its node may be gone under it
                    log.debug("job ended by the shutdown: %s", exc)
                elif not isinstance(exc, Ros2Error):
                    log.exception("job failed")
                if on_error is not None:
                    message = one_line(exc)
                    self.post(lambda: on_error(message))
                else:
                    self._wake.set()
                return
            if on_done is not None:
                self.post(lambda: on_done(result))
            else:
                self._wake.set()  # the page shows the effect at once, not at the next tick

        if lane is None:
            threading.Thread(target=body, name="ui-job", daemon=True).start()
            return
        with self._lanes_lock:
            if self._closed:
                return
            executor = self._lanes.get(lane)
            if executor is None:
                executor = ThreadPoolExecutor(1, thread_name_prefix=f"ui-lane-{lane}")
                self._lanes[lane] = executor
            executor.submit(body)

    # -- the UI thread -----------------------------------------------------------

    def wait(self, timeout: float) -> bool:
        """Sleep until something was posted or a job ended, at most ``timeout`` s."""
        woken = self._wake.wait(timeout)
        if woken:  # a wake that lands after a timeout stays set for the next wait
            self._wake.clear()
        return woken

    def apply_pending(self) -> int:
        """Run every posted intent in order; one failing intent stops no other.

        Returns how many of them asked for a refresh.
        """
        applied = 0
        while True:
            try:
                intent, refresh = self._intents.get_nowait()
            except queue.Empty:
                return applied
            applied += refresh
            try:
                intent()
            except Exception:  # a bug in one panel (or a forged widget value) freezes nothing
                log.exception("UI intent failed")

    def close(self) -> None:
        with self._lanes_lock:
            self._closed = True
            lanes, self._lanes = list(self._lanes.values()), {}
        for executor in lanes:
            executor.shutdown(wait=False, cancel_futures=True)


class FullPasses:
    """Which passes of the UI thread ask for the graph again and refresh the calm panels
    (``app.ui.Panel``) too: every pass after something happened (a click, a job's end)
    and for ``settle`` seconds after the node list changed (a node's topics follow its
    name), otherwise one pass every ``period`` seconds. The other passes refresh only
    the live panels (the stage, echo, plots), which is what an idle lesson costs."""

    def __init__(self, period: float, settle: float) -> None:
        self._period = period
        self._settle = settle
        self._due = 0.0
        self._settle_until = 0.0

    def due(self, now: float, *, happened: bool, nodes_changed: bool) -> bool:
        if nodes_changed:
            self._settle_until = now + self._settle
        if happened or now < self._settle_until or now >= self._due:
            self._due = now + self._period
            return True
        return False

    def settling(self, now: float) -> bool:
        """Whether the node list changed less than ``settle`` seconds ago."""
        return now < self._settle_until


class HiddenPasses:
    """Which passes of the UI thread refresh the tools no page shows (``app.ui.Panel``):
    every pass after something happened or while the node list settles, otherwise one
    full pass every ``period`` seconds (so a calm hidden tool is refreshed too)."""

    def __init__(self, period: float) -> None:
        self._period = period
        self._due = 0.0

    def due(self, now: float, *, eventful: bool, full: bool) -> bool:
        if eventful or (full and now >= self._due):
            self._due = now + self._period
            return True
        return False
