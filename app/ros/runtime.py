"""The dashboard's own ROS participant: one context, one node, one executor thread.

``rclpy`` is initialised on the calling (main) thread with its signal
handlers off (the CLI owns SIGINT/SIGTERM); the observer node
``/classroom_dashboard`` is spun by one executor in one thread.
Everything else in the dashboard creates its subscriptions and clients on
``runtime.node`` and never spins it.

The executor is single-threaded on purpose: every dashboard callback is short
(it records a message or a result and returns; waiting happens in worker
threads on futures), and rclpy's MultiThreadedExecutor costs so much per
callback that it took about 3,500 small messages a second here against about
8,400 for the single-threaded one (10 topics at 1 kHz, measured side by side).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import traceback
from collections.abc import Iterator
from contextlib import contextmanager, suppress

import rclpy
from rclpy._rclpy_pybind11 import RCLError
from rclpy.context import Context
from rclpy.exceptions import InvalidHandle
from rclpy.executors import (
    ConditionReachedException,
    Executor,
    ExternalShutdownException,
    ShutdownException,
    SingleThreadedExecutor,
)
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import try_shutdown

from nodes.common.parameter_guard import guard_parameter_services

DASHBOARD_NODE_NAME = "classroom_dashboard"
# The native teardown of a participant takes milliseconds; this long means it hung.
TEARDOWN_SEC = 10.0
# A file that a watchdog's last words are appended to as well (see process_watchdog).
WATCHDOG_LOG_VARIABLE = "CLASSROOM_WATCHDOG_LOG"


class RosRuntime:
    """``node`` in a context of its own, spun by one executor thread until ``shutdown``.

    ``domain_id`` None: the environment's domain. ``quiet``: the node serves no
    parameters and writes no /rosout (a side participant, see side_participant).
    """

    def __init__(
        self,
        node_name: str = DASHBOARD_NODE_NAME,
        *,
        domain_id: int | None = None,
        quiet: bool = False,
    ) -> None:
        # Our node serves parameters too: a client sending an unknown parameter
        # type must get a refusal, not end the dashboard (rclpy 7.1.6 bug).
        guard_parameter_services()
        self.context = Context()
        no_signals = SignalHandlerOptions.NO  # the CLI owns SIGINT and SIGTERM
        rclpy.init(context=self.context, domain_id=domain_id, signal_handler_options=no_signals)
        self.node = Node(
            node_name,
            context=self.context,
            start_parameter_services=not quiet,
            enable_rosout=not quiet,
        )
        self.executor = SingleThreadedExecutor(context=self.context)
        self.lost_waits = 0  # waits lost to an entity destroyed meanwhile (see _spin)
        self.callback_errors = 0  # callbacks that raised; each place is told once (see _spin)
        self._reported: set[tuple[str, str, int]] = set()
        self.executor.add_node(self.node)
        self._stopping = threading.Event()  # ends _spin with nothing destroyed under it
        self._thread = threading.Thread(target=self._spin, name=f"ros-{node_name}", daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        while True:
            try:
                spin_until(self.executor, self._stopping)
                return
            except (ExternalShutdownException, KeyboardInterrupt):
                return
            except InvalidHandle:
                # rclpy 7.1.6 race: another thread destroyed a publisher or subscription
                # (its QoS event handler) while the executor was building its wait set;
                # the handler is skipped when entered but still added to the set, which
                # raises here. Only that one wait is lost: spin on, never die silently.
                self.lost_waits += 1
            except RCLError as exc:
                # The same race for an action client (a goal's client destroyed by the
                # worker that sent it): rclpy adds its freed handle to the wait set.
                if _lost_wait(exc):
                    self.lost_waits += 1
                else:
                    self._report(exc)
            except Exception as exc:
                self._report(exc)

    def _report(self, exc: BaseException) -> None:
        """One faulty callback (ours, on a message we did not expect) would otherwise stop
        every panel, check and 3D view at once. Say it, once per place, on stderr (the
        dashboard's log); the caller spins on."""
        self.callback_errors += 1
        where = _where_raised(exc)
        if where not in self._reported:
            self._reported.add(where)
            print(
                f"[ERROR] a callback of /{self.node.get_name()} raised (spinning on):\n"
                + "".join(traceback.format_exception(exc)),
                file=sys.stderr,
                flush=True,
            )

    def shutdown(self, timeout: float = 2.0, teardown_sec: float = TEARDOWN_SEC) -> None:
        """Executor first, then the node, then the context: never unbounded.

        The executor thread is told to stop and gets ``timeout`` s to leave; only
        then are the executor (rclpy 7.1.6's ``Executor.shutdown`` destroys its
        guard conditions without waiting for the spinning thread) and the node
        destroyed: destroying what that thread still waits on is the race rclpy
        cannot handle (a SIGSEGV of tf2_monitor on SIGTERM, CI of 2026-12-04).
        The native teardown (Fast DDS deleting its readers and writers) runs
        with the GIL held, so no Python thread could stop it if it hung: a
        watchdog process ends this process after ``teardown_sec`` s instead,
        saying so on stderr.
        """
        self._stopping.set()
        self.executor.wake()  # out of its wait, to see the flag
        self._thread.join(timeout)
        with process_watchdog(teardown_sec, f"ROS teardown of /{self.node.get_name()}"):
            if not self._thread.is_alive():
                self.executor.shutdown(timeout_sec=timeout)
                self.node.destroy_node()
            try_shutdown(context=self.context)


def spin_until(executor: Executor, stopping: threading.Event) -> None:
    """``executor.spin()`` until ``stopping`` is set and the executor is woken.

    ``Executor.spin()`` ends only through ``Executor.shutdown()``, which destroys the
    guard conditions the spinning thread still waits on. Raises what a callback
    raised, and ExternalShutdownException once the context is shut down.
    """
    stopped = stopping.is_set  # one object: the executor reuses its wait while args are equal
    while not stopped():
        try:
            handler = executor.wait_for_ready_callbacks(None, None, stopped)[0]
        except (ConditionReachedException, ShutdownException):
            return
        handler()
        handler.result()  # raises what the callback raised


def _lost_wait(exc: RCLError) -> bool:
    """An entity freed by another thread while the executor built its wait set."""
    return "to wait set" in str(exc) and "pointer is invalid" in str(exc)


def _where_raised(exc: BaseException) -> tuple[str, str, int]:
    """The exception's type and the innermost line that raised it."""
    frames = traceback.extract_tb(exc.__traceback__)
    last = frames[-1] if frames else None
    return (type(exc).__name__, last.filename if last else "", last.lineno or 0 if last else 0)


@contextmanager
def process_watchdog(seconds: float, what: str) -> Iterator[None]:
    """End this process (SIGKILL, after a line on stderr) if the block outlasts ``seconds``.

    The watchdog is a shell in its own session (it keeps running while native
    code holds our GIL); when the block ends in time, its whole group is killed.
    The line also goes to the file ``$CLASSROOM_WATCHDOG_LOG`` names, if any: a
    process whose stderr is captured in memory (a test runner's) loses it.
    """
    pid = os.getpid()
    line = f"{what} hung for {seconds:g} s: ending process {pid}"
    also = os.environ.get(WATCHDOG_LOG_VARIABLE, "")
    script = (
        f'sleep {seconds:g}; echo "$1" >&2; '
        f'[ -z "$2" ] || echo "$(date +%H:%M:%S) $1" >> "$2"; kill -KILL {pid}'
    )
    guard = subprocess.Popen(
        ["/bin/sh", "-c", script, "watchdog", line, also],
        start_new_session=True,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
    )
    try:
        yield
    finally:
        with suppress(ProcessLookupError):
            os.killpg(guard.pid, signal.SIGKILL)
        guard.wait()
