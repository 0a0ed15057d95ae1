"""spin_node: the main() that the nodes of this course share.

It is the skeleton ``nodes/minimal_node.py`` writes out in full: start ROS
(``rclpy.init`` reads ``--ros-args``), create the node, spin it until Ctrl+C
(SIGINT) or SIGTERM, then destroy the node and shut ROS down, cleaning up only
what was made (a signal can arrive at any point of start-up). A node's
``main`` stays one line, and what differs says so::

    def main(args=None) -> None:
        spin_node(Talker, args)                                 # rclpy.spin(node)
        spin_node(Server, args, executor=MultiThreadedExecutor)  # executor.spin()
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Callable
from typing import TypeVar

import rclpy
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node

NodeT = TypeVar("NodeT", bound=Node)

EXIT_BAD_PARAMETER = 2
RCLError = _rclpy.RCLError


def spin_node(
    make_node: Callable[[], NodeT],
    args: list[str] | None = None,
    *,
    executor: type[Executor] | Callable[[NodeT], Executor] | None = None,
    before_shutdown: Callable[[NodeT], None] | None = None,
    program: str | None = None,
) -> None:
    """Run ``make_node()`` until Ctrl+C or SIGTERM.

    - ``executor``: an executor class (or a method of the node) to spin on
      with ``executor.add_node(node)`` and ``executor.spin()``; by default
      ``rclpy.spin(node)``, a single-threaded executor.
    - ``before_shutdown(node)``: called when spinning ends, before the
      executor shuts down (which waits for callbacks still running): the
      place to wake a callback that sleeps.
    - ``program``: a ValueError raised while the node is made (a start-up
      parameter it cannot use) prints ``<program>: error: <reason>`` and
      exits with status 2, instead of a traceback.
    """
    node: NodeT | None = None
    spinner: Executor | None = None
    spinning = threading.Event()
    _sigint_ends_spin_quietly(spinning)
    try:
        rclpy.init(args=args)
        try:
            node = make_node()
        except ValueError as exc:
            if program is None:
                raise
            print(f"{program}: error: {exc}", file=sys.stderr)
            raise SystemExit(EXIT_BAD_PARAMETER) from None
        spinning.set()
        if executor is None:
            rclpy.spin(node)
        else:
            spinner = _make_executor(executor, node)
            spinner.add_node(node)
            spinner.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl+C (SIGINT) or SIGTERM: leave quietly
    except RCLError:
        if rclpy.ok():
            raise
        # The signal shut ROS down while a callback was still publishing: leave quietly too.
    finally:
        _teardown(node, spinner, before_shutdown)


# A node ends at most this long after Ctrl+C or SIGTERM, whatever hangs in its teardown.
TEARDOWN_SEC = 5


def _teardown(
    node: NodeT | None,
    spinner: Executor | None,
    before_shutdown: Callable[[NodeT], None] | None,
) -> None:
    """``before_shutdown``, the executor, the node, then ROS: in bounded time.

    The kernel's alarm bounds it: rclpy's native teardown (destroying the
    readers and writers in Fast DDS) runs with the GIL held, so when it hangs
    no Python thread or signal handler can run; SIGALRM with its default
    action ends the process. The supervisor asked for the stop, so it reads
    the ending as stopped. Off the main thread (a node spun in a test's
    thread) no alarm is set: that process has its own way out.
    """
    armed = threading.current_thread() is threading.main_thread()
    if armed:
        signal.signal(signal.SIGALRM, signal.SIG_DFL)
        signal.alarm(TEARDOWN_SEC)
    try:
        if node is not None and before_shutdown is not None:
            before_shutdown(node)
        if spinner is not None:
            spinner.shutdown(timeout_sec=1.0)
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    finally:
        if armed:
            signal.alarm(0)


def _sigint_ends_spin_quietly(spinning: threading.Event) -> None:
    """Ctrl+C while spinning ends the spin the way SIGTERM does, not by KeyboardInterrupt.

    rclpy's own signal handler shuts the context down, so spin() returns by
    ExternalShutdownException. Python's default handler would also raise
    KeyboardInterrupt at whatever line runs at that moment; inside rclpy's
    executor that can be halfway through building a Task, whose ``__del__``
    then prints a traceback as the process ends. Before spinning (start-up),
    Ctrl+C stays a KeyboardInterrupt. Set before ``rclpy.init``, which
    chains its handler to this one (setting a handler afterwards would
    replace rclpy's).
    """
    if threading.current_thread() is not threading.main_thread():
        return

    def on_sigint(signum: int, frame: object) -> None:
        if not spinning.is_set():
            raise KeyboardInterrupt

    signal.signal(signal.SIGINT, on_sigint)


def _make_executor(factory: type[Executor] | Callable[[NodeT], Executor], node: NodeT) -> Executor:
    """``MultiThreadedExecutor`` (a class) takes no node; ``ExecutorDemo.make_executor`` does."""
    if isinstance(factory, type):
        return factory()
    return factory(node)
