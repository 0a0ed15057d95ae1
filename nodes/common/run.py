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

import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import FrameType
from typing import Any, TypeVar

import rclpy
from rclpy.exceptions import InvalidHandle, NotInitializedException
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions, install_signal_handlers

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
    try:
        with stopped_quietly():
            init_ros(args)
            try:
                node = make_node()
            except ValueError as exc:
                if program is None or not rclpy.ok():
                    raise
                print(f"{program}: error: {exc}", file=sys.stderr)
                raise SystemExit(EXIT_BAD_PARAMETER) from None
            if executor is not None:
                spinner = _make_executor(executor, node)
                spinner.add_node(node)
            ros_started(spinner)
            if spinner is None:
                rclpy.spin(node)
            else:
                spinner.spin()
    finally:
        _teardown(node, spinner, before_shutdown)


@contextmanager
def stopped_quietly() -> Iterator[None]:
    """Ctrl+C (SIGINT) or SIGTERM ends the block quietly, whatever ROS call it interrupts.

    rclpy's signal thread shuts the context down while the main thread may be
    inside any ROS call: spinning (ExternalShutdownException), publishing or
    waiting for a server (RCLError: "context is invalid"), creating an entity
    (ValueError) or a node (NotInitializedException), using one already
    destroyed (InvalidHandle), or starting to spin (AttributeError: the global
    executor is gone). With ROS still up, those are real errors and go on.
    """
    global _ending
    try:
        yield
    except (KeyboardInterrupt, ExternalShutdownException):
        _ending = True
    except (RCLError, ValueError, InvalidHandle):
        # Ending before asking rclpy: the SIGTERM that shut the context down may have its
        # Python handler run inside rclpy.ok(), where its KeyboardInterrupt would escape
        # this clause (seen: view_frames stopped while creating its node).
        _ending = True
        if rclpy.ok():
            raise
    except NotInitializedException:
        # A node made after the signal shut the context down (seen: planner_server's
        # costmap making its tf listener's node, SIGTERM during start-up). A program that
        # never called rclpy.init() has no context handle: that error goes on.
        _ending = True
        if rclpy.ok() or rclpy.get_default_context().handle is None:
            raise
    except AttributeError as exc:
        # rclpy.spin(node) just after the signal shut the context down: rclpy's global
        # executor is then None, and spin() fails on None.add_node (seen: amcl, SIGTERM
        # between making its node and spinning it).
        _ending = True
        if rclpy.ok() or "'NoneType'" not in str(exc):
            raise
    finally:
        _ending = True  # first, in one store: a late signal in what follows raises nothing
        _start.end()  # a signal during the teardown is ignored, not raised


def init_ros(args: list[str] | None = None) -> None:
    """``rclpy.init`` without rclpy's signal handlers, which ``ros_started`` installs.

    rclpy's handlers shut the context down from a native thread of theirs, at
    once: during start-up that races the main thread creating the node's
    publishers, services and action servers in Fast DDS (seen: a traceback
    from ActionServer(), a SIGSEGV). Until the node is made, Ctrl+C and
    SIGTERM are held instead and honoured by ``ros_started``: the node is
    made whole first. Interrupting a constructor leaves what it started
    running (sim_world's physics thread then crashed the exit, SIGSEGV). A
    second signal interrupts the start-up where it is (KeyboardInterrupt), for
    one that hangs; the supervisor's second signal is SIGTERM, then SIGKILL.
    """
    _start.clear()
    _stop_signals_held_until_started()
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)


def ros_started(spinner: Executor | None = None) -> None:
    """The node is made: from now on rclpy's handlers end the spin (the context shuts down).

    A stop held during start-up ends it here, at a safe point
    (KeyboardInterrupt). rclpy's handlers go in before the start counts as
    done, so a signal in between is held, not lost.

    ``spinner`` is the executor that will spin the node, made already; by
    default rclpy's global one, which ``rclpy.spin`` uses, is made here. It
    must exist before the handlers go in: rclpy's signal thread shutting the
    context down in the middle of ``Executor()`` leaves a half-made guard
    condition whose ``__del__`` prints a traceback (seen: ci33, turtlesim
    stopped between this call and ``rclpy.spin``).
    """
    _stop_watch.spinning = spinner if spinner is not None else rclpy.get_global_executor()
    install_signal_handlers(SignalHandlerOptions.ALL)
    _stop_watch.start()
    _start.end()
    if _start.requested:
        raise KeyboardInterrupt


class _StartUp:
    """Stop signals seen while the node is being made (main thread only)."""

    done = True
    requested = 0

    def clear(self) -> None:
        self.done, self.requested = False, 0

    def end(self) -> None:
        self.done = True


_start = _StartUp()


class _StopWatch:
    """Makes sure a stop signal ends the spin, whatever the order rclpy's thread works in.

    On Ctrl+C or SIGTERM rclpy's signal thread first wakes the executors, *then* shuts
    the context down. An executor that wakes in between finds ROS still up and waits
    again, with nothing left to wake it: the node ignores the signal for good (seen on a
    loaded machine: turtle_tf2_broadcaster, sim_arm_state_publisher and
    turtle_mimic_multisim still in rclpy.spin 20 s after SIGTERM). So a stop signal
    also wakes this thread, which waits for the context to go down (taking it down
    itself after ``GRACE_SEC``) and then wakes the spinning executor once more. The
    signal handler only writes a byte to a pipe: no lock a signal could interrupt.
    """

    GRACE_SEC = 1.0

    def __init__(self) -> None:
        self.spinning: Executor | None = None
        self._pipe: tuple[int, int] | None = None

    def start(self) -> None:
        if self._pipe is not None:
            return
        self._pipe = os.pipe()
        os.set_blocking(self._pipe[1], False)
        threading.Thread(target=self._watch, name="stop-watch", daemon=True).start()

    def stop_requested(self) -> None:
        """From the signal handler: a write, nothing that takes a lock."""
        if self._pipe is not None:
            try:
                os.write(self._pipe[1], b"x")
            except OSError:  # full (signals already told) or closed: nothing to add
                pass

    def _watch(self) -> None:
        assert self._pipe is not None
        os.read(self._pipe[0], 1)
        context = rclpy.get_default_context()
        deadline = time.monotonic() + self.GRACE_SEC
        while context.ok() and time.monotonic() < deadline:
            time.sleep(0.02)
        try:
            context.try_shutdown()  # already down (rclpy's thread did it): nothing happens
            if self.spinning is not None:
                self.spinning.wake()
        except Exception:  # the main thread tore it all down meanwhile: it has ended
            pass


_stop_watch = _StopWatch()


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
            # Stopped. The interpreter's exit puts the default handlers back: a second
            # Ctrl+C or SIGTERM then (a supervisor escalating) would turn this clean
            # end into "killed by SIGTERM".
            for sig in (signal.SIGINT, signal.SIGTERM):
                signal.signal(sig, signal.SIG_IGN)


def _stop_signals_held_until_started() -> None:
    """Ctrl+C and SIGTERM: held during start-up (see ``init_ros``), then left to rclpy.

    A KeyboardInterrupt raised at whatever line runs at that moment is not
    safe: inside an import it is "ignored" and the start-up goes on (seen:
    a node that then ignored SIGTERM for good), inside rclpy's executor it
    can leave a half-built Task whose ``__del__`` prints a traceback. So
    while spinning this handler does nothing: rclpy's own, chained to it,
    shuts the context down and spin() returns by ExternalShutdownException.
    After ``rclpy.try_shutdown`` (which puts this one back) a late signal is
    ignored, so the teardown ends as it began.
    """
    if threading.current_thread() is not threading.main_thread():
        return

    def on_stop(signum: int, frame: object) -> None:
        if _start.done:
            _stop_watch.stop_requested()
            return
        _start.requested += 1
        if _start.requested > 1:
            raise KeyboardInterrupt

    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, on_stop)


def spin_threads_end_quietly() -> None:
    """A thread spinning an executor ends without a traceback when a signal shuts ROS down.

    For programs that spin in a thread of their own (the tf2 tools): on Ctrl+C
    or SIGTERM rclpy shuts the context down and ``executor.spin()`` raises
    ExternalShutdownException in that thread, which Python would print as
    an uncaught exception while the program itself ends normally.
    """
    previous = threading.excepthook

    def hook(args: threading.ExceptHookArgs) -> None:
        stopped = issubclass(args.exc_type, ExternalShutdownException) or (
            not rclpy.ok() and issubclass(args.exc_type, (RCLError, InvalidHandle))
        )
        if stopped:
            return
        previous(args)

    threading.excepthook = hook


def run_program(main: Callable[[], int | None]) -> None:
    """Run a ros_python program (a tf2 tool, robot_state_publisher ...) as a catalog node.

    Those programs catch Ctrl+C (KeyboardInterrupt) themselves but not
    SIGTERM, so SIGTERM is made Ctrl+C here (``interrupt_outside_imports``).
    ROS errors of a context the signal shut down meanwhile (a node still
    being made, a spin thread) end the program quietly too, as in ``spin_node``.
    """
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, interrupt_outside_imports)
    spin_threads_end_quietly()
    sys.unraisablehook = _quiet_half_built
    code: int | None = 0
    global _ending
    try:
        with stopped_quietly():
            code = main()
            # Ending (rclpy's own handler may have ended main): a signal from now on,
            # however late its Python handler runs, must not raise outside this block.
            # One store, not Event.set(): a handler can run inside a Python-level call.
            _ending = True
    finally:
        _ending = True
        _interrupted.set()
        # A late signal (a retry, a supervisor's second SIGTERM) must not raise in the
        # interpreter's own shutdown, which prints it as a traceback.
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)
    sys.exit(code)


def _quiet_half_built(unraisable: Any) -> None:
    """Once the program ends on a signal, an rclpy object the signal interrupted while it
    was being made (an executor without its attributes) fails in ``__del__``: not news."""
    owner = getattr(unraisable.object, "__module__", "") or ""
    if _ending and isinstance(unraisable.exc_value, AttributeError) and owner.startswith("rclpy"):
        return
    sys.__unraisablehook__(unraisable)


RETRY_SIGNAL_SEC = 0.05


def interrupt_outside_imports(signum: int, frame: FrameType | None) -> None:
    """Ctrl+C's KeyboardInterrupt, raised where it can end the program.

    Raised inside Python's import machinery (an import still under way as
    the node joins the graph, or its module-lock clean-up running in garbage
    collection) it is printed as "Exception ignored ... KeyboardInterrupt"
    with a traceback and lost. Raised inside an rclpy constructor it leaves a
    half-made object whose ``__del__`` prints a traceback (seen: "Exception
    ignored in Executor.__del__ ... '_sigint_gc'"). In both the signal is sent
    again a moment later.
    Raised once: a later signal would interrupt the program's own clean-up (a
    supervisor that must stop a hung one sends SIGKILL next).
    """
    if _ending or _interrupted.is_set():
        return  # the program is ending already: one KeyboardInterrupt is enough
    at = frame
    while at is not None:
        if _unsafe_to_interrupt(at):
            retry = threading.Timer(RETRY_SIGNAL_SEC, os.kill, (os.getpid(), signum))
            retry.daemon = True
            retry.start()
            return
        at = at.f_back
    _interrupted.set()
    raise KeyboardInterrupt


def _unsafe_to_interrupt(frame: FrameType) -> bool:
    """Inside an import, or inside the ``__init__`` of one of rclpy's classes."""
    code = frame.f_code
    if code.co_filename.startswith("<frozen importlib"):
        return True
    return code.co_name == "__init__" and f"{os.sep}rclpy{os.sep}" in code.co_filename


_interrupted = threading.Event()  # interrupt_outside_imports has raised its one interrupt
_ending = False  # main has returned or its block has ended: signals raise nothing now


def _make_executor(factory: type[Executor] | Callable[[NodeT], Executor], node: NodeT) -> Executor:
    """``MultiThreadedExecutor`` (a class) takes no node; ``ExecutorDemo.make_executor`` does."""
    if isinstance(factory, type):
        return factory()
    return factory(node)
