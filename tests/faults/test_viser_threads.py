"""viser handles set from many threads while browsers come and go (issue 38).

viser 1.1.1 sets an ``asyncio.Event`` from whichever thread sets a handle
(``AsyncMessageBuffer.push``) while the loop thread adds and removes that
event's waiters, one per browser: under load our UI thread died with
``RuntimeError: deque mutated during iteration``. app/viser_threads.py,
installed by ``make_server``, hands those sets to the loop. Real server, real
websocket clients (tests/wire_client.py); no DDS.
"""

from __future__ import annotations

import math
import random
import sys
import threading
import time
import traceback
from collections import Counter
from collections.abc import Callable
from typing import Any

import pytest
import viser

from tests.conftest import wait_until
from tests.faults.helpers import record
from tests.wire_client import CAMERA_REPORT, WireClient

STEADY_CLIENTS = 12  # stay connected all along and must see every kind of update
CHURNERS = 4  # threads that connect a client, keep it briefly, and close it, over and over
UPDATERS = 10  # threads that set handles
ORBIT_SEC = 0.02  # each steady browser reports its camera at 50 Hz, as one being orbited
# The updaters set their handles together, once a tick, and the broadcast buffer
# idles in between: every browser's generator is then waiting on the event, so
# one set walks all those waiters while the others' call_soon_threadsafe wakes
# the loop to remove them. A steady flood never lets the generators wait (no
# crash in 60 s); 5-set bursts a tick crashed in 1 run of 5. Camera reports
# keep the loop thread busy.
# Without the fix, on 2 cores at load 11-18: the first crash came after 1.3-18.4 s
# in 8 of 9 runs (one passed 30 s); 16 clients instead of 12 crashed less (load).
TICK_SEC = 0.03
RUN_SEC = 60.0
# A short GIL switch interval preempts a thread inside Event.set's walk over the
# waiters far more often (at the default 5 ms: no crash in 60 s).
SWITCH_INTERVAL = 1e-5
# What this test looks for is a crash, not speed: on a loaded CI machine (2026-12-01) a
# churner's websocket handshake took more than websockets' default 10 s while ~40
# threads at that switch interval shared the GIL with the server's loop. A loop that
# hangs still fails: its handshakes outlast this, and the churner's thread its join.
HANDSHAKE_TIMEOUT = 40.0


def _markdown_updater(server: viser.ViserServer, n: int) -> Callable[[int], None]:
    handle = server.gui.add_markdown(f"updater {n}")

    def step(i: int) -> None:
        handle.content = f"updater {n}: {i}"

    return step


def _number_updater(server: viser.ViserServer, n: int) -> Callable[[int], None]:
    handle = server.gui.add_number(f"number {n}", initial_value=0)

    def step(i: int) -> None:
        handle.value = i

    return step


def _scene_updater(server: viser.ViserServer, n: int) -> Callable[[int], None]:
    frame = server.scene.add_frame(f"/stress/frame_{n}")
    extra: list[Any] = []

    def step(i: int) -> None:
        frame.position = (0.01 * (i % 100), 0.0, 0.0)
        if i % 20 == 0:  # nodes come and go too, as a panel's markers do
            if extra:
                extra.pop().remove()
            else:
                extra.append(server.scene.add_icosphere(f"/stress/ball_{n}", radius=0.1))

    return step


KINDS = (_markdown_updater, _number_updater, _scene_updater)


def test_handles_set_from_many_threads_while_clients_come_and_go(bare_server: viser.ViserServer):
    url = f"ws://127.0.0.1:{bare_server.get_port()}"
    errors: list[str] = []
    errors_lock = threading.Lock()
    stop = threading.Event()
    started = time.monotonic()
    first_error_at: list[float] = []

    def fail(what: str) -> None:
        with errors_lock:
            if not first_error_at:
                first_error_at.append(time.monotonic() - started)
            errors.append(what)
        stop.set()  # the first crash is the answer: no need to run on

    def on_loop_error(loop: Any, context: dict[str, Any]) -> None:
        exc = context.get("exception")
        detail = "".join(traceback.format_exception(exc)) if exc else ""
        fail(f"event loop: {context.get('message')}\n{detail}")

    bare_server.get_event_loop().set_exception_handler(on_loop_error)
    steps = [KINDS[n % len(KINDS)](bare_server, n) for n in range(UPDATERS)]
    steady: list[WireClient] = []
    pushes = [0] * UPDATERS
    connects = [0] * CHURNERS
    handshakes: list[float] = []  # seconds each churner's connection took to open

    def update(n: int) -> None:
        i = 0
        try:
            while not stop.is_set():
                steps[n](i)
                i += 1
                time.sleep(TICK_SEC - time.monotonic() % TICK_SEC)  # all updaters wake together
        except BaseException:
            fail(f"updater {n} after {i} sets:\n{traceback.format_exc()}")
        pushes[n] = i

    def orbit(client: WireClient) -> None:
        turn = 0.0
        try:
            while not stop.wait(ORBIT_SEC):
                turn += 0.05
                orbit = (3 * math.cos(turn), 3 * math.sin(turn), 3.0)
                client.send({**CAMERA_REPORT, "position": orbit})
        except BaseException:
            fail(f"orbit:\n{traceback.format_exc()}")

    def churn(n: int) -> None:
        rng = random.Random(n)
        try:
            while not stop.is_set():
                asked = time.monotonic()
                client = WireClient(url, open_timeout=HANDSHAKE_TIMEOUT)
                handshakes.append(time.monotonic() - asked)
                connects[n] += 1
                stop.wait(rng.uniform(0.02, 0.2))
                client.close()
        except BaseException:
            fail(f"churner {n}:\n{traceback.format_exc()}")

    threads = [threading.Thread(target=update, args=(n,), daemon=True) for n in range(UPDATERS)]
    threads += [threading.Thread(target=churn, args=(n,), daemon=True) for n in range(CHURNERS)]
    old_interval = sys.getswitchinterval()
    try:
        steady.extend(WireClient(url) for _ in range(STEADY_CLIENTS))
        threads += [threading.Thread(target=orbit, args=(c,), daemon=True) for c in steady]
        sys.setswitchinterval(SWITCH_INTERVAL)
        started = time.monotonic()  # the time to a first crash counts from here
        try:
            for thread in threads:
                thread.start()
            stop.wait(RUN_SEC)
            stop.set()
            for thread in threads:
                thread.join(timeout=HANDSHAKE_TIMEOUT + 10)
        finally:
            sys.setswitchinterval(old_interval)
        elapsed = time.monotonic() - started
        assert not errors, f"{len(errors)} errors, first after {first_error_at[0]:.2f} s:\n" + (
            "\n".join(errors[:3])
        )
        assert not [t.name for t in threads if t.is_alive()], "a stress thread hung"

        # Not an empty run: every steady client saw GUI and scene updates, and a
        # last one reaches all of them promptly once the storm is over.
        for client in steady:
            assert client.closed_reason is None, client.closed_reason
            with client.lock:
                updates = client.counts["GuiUpdateMessage"], client.counts["SetPositionMessage"]
            assert min(updates) > 100, updates
        markdown = bare_server.gui.add_markdown("calm")
        sent = time.monotonic()
        markdown.content = "the last word"
        wait_until(
            lambda: all("the last word" in c.markdown() for c in steady),
            timeout=5,
            interval=0.005,
            what="every steady client to see the last markdown",
        )
        latency = time.monotonic() - sent
    finally:
        for client in steady:
            client.close()
    record(
        "viser handles from many threads",
        seconds=round(elapsed, 1),
        steady_clients=STEADY_CLIENTS,
        connects=sum(connects),
        slowest_handshake_s=round(max(handshakes, default=float("nan")), 2),
        handle_sets=sum(pushes),
        sets_per_s=round(sum(pushes) / elapsed),
        frames_per_client=min(c.frames for c in steady),
        last_update_ms=round(latency * 1000, 1),
    )


def test_a_test_client_closes_with_one_thread_joining_its_reader(
    bare_server: viser.ViserServer, monkeypatch: pytest.MonkeyPatch
):
    """CI once lost a churner to CPython 3.11's race between two joiners of one thread.

    websockets joins its event thread in ``recv()``, in ``close()`` and in its
    keepalive thread's sleep (see tests/wire_client.frames_until_closed). Count
    the threads inside ``join`` of one thread at once: when one thread read and
    another closed, every close made it 2.
    """
    joining: Counter[int] = Counter()
    most = [0]
    lock = threading.Lock()
    real_join = threading.Thread.join

    def counted_join(thread: threading.Thread, timeout: float | None = None) -> None:
        with lock:
            joining[id(thread)] += 1
            most[0] = max(most[0], joining[id(thread)])
        try:
            real_join(thread, timeout)
        finally:
            with lock:
                joining[id(thread)] -= 1

    monkeypatch.setattr(threading.Thread, "join", counted_join)
    url = f"ws://127.0.0.1:{bare_server.get_port()}"
    for _ in range(5):
        client = WireClient(url)
        wait_until(lambda c=client: c.frames > 0, timeout=10, what="the client's first frame")
        client.close()
    assert most[0] == 1, f"{most[0]} threads joined one thread at once"
