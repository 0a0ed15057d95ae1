"""The supervisor: sole owner of the tutorial node processes.

Each catalog node runs as ``python -m nodes.<module> --ros-args ...`` in its
own process group, as ``ros2 run`` would start it. Stopping escalates
SIGINT -> SIGTERM -> SIGKILL with timeouts; every child is reaped. Children
get a parent-death signal, so they end even when the dashboard is killed with
SIGKILL. Output is kept in a bounded buffer per node.

Threads: children are spawned from one long-lived thread (the parent-death
signal is tied to the *thread* that forked), each child has one reader thread
that also reaps it, and stops escalate in short-lived threads. All state
lives in ``_Process`` objects guarded by one lock; ``start`` holds a second
lock across "is it running?" and the spawn, so two concurrent starts of one
node make one process, never two with the first one lost.
"""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from concurrent.futures import TimeoutError as FutureTimeout  # not TimeoutError on 3.10
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path

from app import PROJECT_ROOT
from app.catalog import CatalogEntry, lookup
from app.containment.policy import RunPolicy
from app.stop_signals import die_with


class NodeState(str, Enum):
    STARTING = "starting"  # process spawned, ROS node not yet seen in the graph
    RUNNING = "running"
    STOPPING = "stopping"
    STOPPED = "stopped"  # stopped on request, or ended by Ctrl+C (even with a traceback)
    EXITED = "exited"  # ended on its own with exit code 0 (e.g. a client)
    CRASHED = "crashed"  # ended on its own with a non-zero code or a signal


@dataclass(frozen=True)
class LearnerProgram:
    """A learner's own node: their file, started like a catalog node.

    The dashboard builds ``argv`` from a file *it* chose (the learner's saved
    exercise); nothing typed in the page reaches it.
    """

    name: str  # the supervisor's key, e.g. "exercise:counter_publisher"
    node_name: str  # the ROS node the program is expected to create
    argv: tuple[str, ...]
    cwd: Path
    # Called with the pid once the process is reaped (contained code: end its forks too).
    after_exit: Callable[[int], object] | None = field(default=None, compare=False)
    # Variables set on top of the supervisor's environment (e.g. AMENT_PREFIX_PATH for a launch).
    env: Mapping[str, str] | None = field(default=None, compare=False)
    # False when ``node_name`` is only a label: a package's executable names its node in
    # its own code, a build makes none. Such a program is running once the graph was
    # looked at while it lived, never "starting" for as long as it runs.
    names_its_node: bool = True


Program = CatalogEntry | LearnerProgram

# The key of a program of the learner's own workspace (`ros2 run <package> <executable>`).
OWN_PROGRAM = "own:/"


def _names_its_node(entry: Program) -> bool:
    return not isinstance(entry, LearnerProgram) or entry.names_its_node


def own_program_key(package: str, executable: str) -> str:
    return f"{OWN_PROGRAM}{package}/{executable}"


ACTIVE_STATES = frozenset({NodeState.STARTING, NodeState.RUNNING, NodeState.STOPPING})


@dataclass(frozen=True)
class NodeStatus:
    """A snapshot of one catalog node's process, safe to hand to any thread."""

    name: str
    state: NodeState
    pid: int | None = None
    exit_code: int | None = None
    started_at: float | None = None
    ended_at: float | None = None
    dropped_lines: int = 0

    @property
    def active(self) -> bool:
        return self.state in ACTIVE_STATES

    def describe(self) -> str:
        """Readable state, e.g. 'crashed (exit code 1)' or 'killed by SIGKILL'."""
        if self.state in (NodeState.CRASHED, NodeState.STOPPED, NodeState.EXITED):
            if self.exit_code is not None and self.exit_code < 0:
                try:
                    sig = signal.Signals(-self.exit_code).name
                except ValueError:
                    sig = f"signal {-self.exit_code}"
                return f"{self.state.value} (killed by {sig})"
            if self.exit_code is not None:
                return f"{self.state.value} (exit code {self.exit_code})"
        if self.state in ACTIVE_STATES and self.pid is not None:
            return f"{self.state.value} (pid {self.pid})"
        return self.state.value


class _Process:
    """Book-keeping for one child; mutated only under the supervisor's lock."""

    def __init__(self, entry: Program, popen: subprocess.Popen[bytes], max_lines: int):
        self.entry = entry
        self.popen = popen
        self.state = NodeState.STARTING
        self.stop_requested = False
        self.started_at = time.time()
        self.ended_at: float | None = None
        self.exit_code: int | None = None
        self.output: deque[str] = deque(maxlen=max_lines)
        self.dropped_lines = 0
        self.done = threading.Event()

    def status(self) -> NodeStatus:
        return NodeStatus(
            self.entry.name,
            self.state,
            self.popen.pid,
            self.exit_code,
            self.started_at,
            self.ended_at,
            self.dropped_lines,
        )


# The last line of a Python traceback when a node ends on Ctrl+C without catching it:
# rclpy raises one or the other depending on where SIGINT finds it (old tutorials
# catch only KeyboardInterrupt). That is a stop, not a crash.
_INTERRUPTS = ("KeyboardInterrupt", "ExternalShutdownException")


def ended_state(code: int, stop_requested: bool, output: Iterable[str]) -> NodeState:
    """How a reaped process ended: stopped (asked to, or on SIGINT), exited, or crashed."""
    if stop_requested:
        return NodeState.STOPPED
    if code == 0:
        return NodeState.EXITED
    if code == -signal.SIGINT:
        return NodeState.STOPPED
    last = next((line.strip() for line in reversed(list(output)) if line.strip()), "")
    error = last.split(":", 1)[0].rsplit(".", 1)[-1]
    return NodeState.STOPPED if code > 0 and error in _INTERRUPTS else NodeState.CRASHED


class Supervisor:
    """Starts, stops and watches catalog nodes. Thread-safe."""

    MAX_LINE_CHARS = 2000
    DRAIN_SEC = 10.0  # after the main process exits, wait this long for its output to end

    def __init__(
        self,
        env: Mapping[str, str],
        *,
        max_log_lines: int = 400,
        sigint_timeout: float = 3.0,
        sigterm_timeout: float = 2.0,
    ) -> None:
        self._env = dict(env)
        self._env.setdefault("PYTHONUNBUFFERED", "1")
        self._env.setdefault("RCUTILS_COLORIZED_OUTPUT", "0")
        self._max_log_lines = max_log_lines
        self.max_log_lines = max_log_lines
        self._timeouts = (sigint_timeout, sigterm_timeout)
        self._lock = threading.Lock()
        self._start_lock = threading.Lock()  # check-then-spawn is one step
        # A state change and its telling are one step, so listeners hear a program's
        # states in the order they happened (a reap racing a Stop told STOPPED first).
        # Reentrant: a listener may ask for a status or a stop.
        self._told_in_order = threading.RLock()
        self._procs: dict[str, _Process] = {}
        self._ended: deque[NodeStatus] = deque(maxlen=500)  # who ended, newest last
        self._spawner = ThreadPoolExecutor(max_workers=1, thread_name_prefix="supervisor-spawn")
        self._closed = False
        self._listeners: list[Callable[[NodeStatus], None]] = []
        # How learner code may run (app.containment.policy), set by whoever serves the
        # page; None refuses it. `ros2 launch` of a learner's launch file reads it.
        self.learner_policy: RunPolicy | None = None

    def on_change(self, listener: Callable[[NodeStatus], None]) -> None:
        """Call ``listener`` with a program's status when it was started, asked to stop and
        reaped (on the thread that did it, in that order): the moments its node joins or
        leaves the graph. A listener must be quick and must not start a program (a start
        waits for the spawner thread, which may be waiting to tell)."""
        self._listeners.append(listener)

    def _tell(self, status: NodeStatus) -> None:
        for listener in list(self._listeners):
            try:
                listener(status)
            except Exception:  # a listener's bug must not stop a start, a stop or a reap
                logging.getLogger(__name__).exception("supervisor listener failed")

    # -- queries -----------------------------------------------------------

    def _known(self, name: str) -> None:
        """Unknown names are an error, not "stopped"."""
        with self._lock:
            if name in self._procs:
                return
        lookup(name)

    def status(self, name: str) -> NodeStatus:
        self._known(name)
        with self._lock:
            proc = self._procs.get(name)
            return proc.status() if proc else NodeStatus(name, NodeState.STOPPED)

    def statuses(self) -> dict[str, NodeStatus]:
        with self._lock:
            return {name: proc.status() for name, proc in self._procs.items()}

    def ended(self) -> list[NodeStatus]:
        """Every process that has ended and been reaped (pid, exit code), newest last."""
        with self._lock:
            return list(self._ended)

    def stale_in_graph(self, node_names: Iterable[str]) -> dict[str, NodeStatus]:
        """Catalog nodes whose process is gone but whose name the graph still lists.

        A node killed without a clean exit stays in DDS discovery until its
        lease runs out (about 20 s with Fast DDS); the panel says so instead
        of showing a dead node as alive.
        """
        seen = set(node_names)
        with self._lock:
            active_names = {p.entry.node_name for p in self._procs.values() if not p.done.is_set()}
            return {
                name: proc.status()
                for name, proc in self._procs.items()
                if proc.done.is_set()
                and proc.entry.node_name in seen
                and proc.entry.node_name not in active_names
            }

    def program(self, name: str) -> Program | None:
        """What ``name`` was last started as (its argv, for a learner's program), if ever."""
        with self._lock:
            proc = self._procs.get(name)
            return proc.entry if proc else None

    def output(self, name: str, last: int | None = None) -> list[str]:
        with self._lock:
            proc = self._procs.get(name)
            lines = list(proc.output) if proc else []
        return lines[-last:] if last else lines

    # -- control -----------------------------------------------------------

    def start(self, name: str, extra_ros_args: Iterable[str] = ()) -> NodeStatus:
        """Start a catalog node; a no-op if it is running, done after the reap if stopping."""
        return self.start_program(lookup(name), extra_ros_args)

    def start_program(self, entry: Program, extra_ros_args: Iterable[str] = ()) -> NodeStatus:
        """Start a catalog entry or a learner's program (same rules as ``start``)."""
        name = entry.name
        while True:
            with self._start_lock:
                with self._lock:
                    if self._closed:
                        raise RuntimeError("the supervisor is shutting down")
                    current = self._procs.get(name)
                    stopping = current is not None and current.state is NodeState.STOPPING
                    if current is not None and current.state in ACTIVE_STATES and not stopping:
                        return current.status()
                if not stopping:
                    return self._spawner.submit(self._spawn, entry, tuple(extra_ros_args)).result()
            # Start right after Stop: the old process is not reaped yet. Starting
            # nothing would be wrong, starting beside it too: wait (bounded by
            # the stop's SIGKILL escalation), then start anew.
            assert current is not None
            current.done.wait()

    def stop(self, name: str) -> Future[NodeStatus]:
        """Ask a node to stop; the future resolves once it has been reaped."""
        self._known(name)
        future: Future[NodeStatus] = Future()
        with self._told_in_order:
            with self._lock:
                proc = self._procs.get(name)
                if proc is None or proc.state not in ACTIVE_STATES:
                    ended = proc.status() if proc else NodeStatus(name, NodeState.STOPPED)
                    future.set_result(ended)
                    return future
                proc.stop_requested = True
                proc.state = NodeState.STOPPING
                stopping = proc.status()
            self._tell(stopping)
        threading.Thread(
            target=self._escalate_stop, args=(proc, future), name=f"stop-{name}", daemon=True
        ).start()
        return future

    def restart(self, name: str) -> NodeStatus:
        self.stop(name).result()
        return self.start(name)

    def note_visible_nodes(self, node_names: Iterable[str]) -> None:
        """Called with the graph's node names: a STARTING node seen there is RUNNING."""
        seen = set(node_names)
        with self._lock:
            for proc in self._procs.values():
                if proc.state is NodeState.STARTING and (
                    proc.entry.node_name in seen or not _names_its_node(proc.entry)
                ):
                    proc.state = NodeState.RUNNING

    def shutdown(self, timeout: float = 4.0) -> None:
        """Stop every child in parallel and reap them all."""
        with self._lock:
            self._closed = True
            names = [n for n, p in self._procs.items() if p.state in ACTIVE_STATES]
        futures = [self.stop(name) for name in names]
        deadline = time.monotonic() + timeout
        for future in futures:
            try:
                future.result(timeout=max(0.1, deadline - time.monotonic()))
            except FutureTimeout:
                pass
        with self._lock:
            leftovers = [p for p in self._procs.values() if not p.done.is_set()]
        for proc in leftovers:  # out of time: no child may outlive us
            self._signal_group(proc, signal.SIGKILL)
            proc.done.wait(1.0)
        self._spawner.shutdown(wait=True)

    # -- internals ---------------------------------------------------------

    def _spawn(self, entry: Program, extra_ros_args: tuple[str, ...]) -> NodeStatus:
        env = self._env
        death_signal = signal.SIGTERM  # our nodes end cleanly when the dashboard dies
        if isinstance(entry, LearnerProgram):
            argv, cwd = list(entry.argv), entry.cwd
            if entry.env:
                env = {**self._env, **entry.env}
            death_signal = signal.SIGKILL  # the learner's code might not (app/stop_signals.py)
        else:
            argv = [sys.executable, "-m", f"nodes.{entry.module}", *entry.argv_tail()]
            if extra_ros_args:
                argv += ([] if entry.ros_args else ["--ros-args"]) + list(extra_ros_args)
            cwd = PROJECT_ROOT
        popen = subprocess.Popen(
            argv,
            cwd=cwd,
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # own process group: signals reach the whole node
            preexec_fn=die_with(os.getpid(), death_signal),
        )
        proc = _Process(entry, popen, self._max_log_lines)
        with self._told_in_order:  # a program that dies at once is told ended after this
            with self._lock:
                self._procs[entry.name] = proc
            threading.Thread(
                target=self._read_and_reap, args=(proc,), name=f"output-{entry.name}", daemon=True
            ).start()
            status = proc.status()
            self._tell(status)
        return status

    def _read_and_reap(self, proc: _Process) -> None:
        """Read the output; reap on another thread, so a process that escaped the group
        and holds the pipe open cannot keep an ended program "running" forever."""
        drained = threading.Event()
        threading.Thread(
            target=self._reap, args=(proc, drained), name=f"reap-{proc.entry.name}", daemon=True
        ).start()
        assert proc.popen.stdout is not None
        for raw in proc.popen.stdout:
            line = raw.decode("utf-8", errors="replace").rstrip("\n")
            if len(line) > self.MAX_LINE_CHARS:
                line = line[: self.MAX_LINE_CHARS] + " …(line cut)"
            with self._lock:
                if len(proc.output) == proc.output.maxlen:
                    proc.dropped_lines += 1
                proc.output.append(line)
        drained.set()

    def _reap(self, proc: _Process, drained: threading.Event) -> None:
        try:  # until the main process has exited; WNOWAIT keeps its pid (and group id) ours
            os.waitid(os.P_PID, proc.popen.pid, os.WEXITED | os.WNOWAIT)
        except ChildProcessError:
            pass
        # Whatever shares its output (a launch file's nodes) may take a moment to end
        # cleanly; a process that escaped the group may hold the pipe for ever.
        drained.wait(self.DRAIN_SEC)
        self._end_group(proc.popen.pid)
        code = proc.popen.wait()
        entry = proc.entry
        if isinstance(entry, LearnerProgram) and entry.after_exit is not None:
            try:
                entry.after_exit(proc.popen.pid)
            except Exception:  # cleaning up after a learner's program must not stop the reap
                logging.getLogger(__name__).exception("after_exit of %s failed", entry.name)
        with self._told_in_order:
            with self._lock:
                proc.exit_code = code
                proc.ended_at = time.time()
                proc.state = ended_state(code, proc.stop_requested, list(proc.output)[-5:])
                self._ended.append(proc.status())
                ended = self._ended[-1]
            proc.done.set()
            self._tell(ended)

    def _escalate_stop(self, proc: _Process, future: Future[NodeStatus]) -> None:
        # SIGINT is Ctrl+C: rclpy nodes leave spin and shut down cleanly, so
        # they also leave the ROS graph at once instead of after a lease timeout.
        for sig, timeout in zip((signal.SIGINT, signal.SIGTERM), self._timeouts, strict=True):
            self._signal_group(proc, sig)
            if proc.done.wait(timeout):
                break
        else:
            self._signal_group(proc, signal.SIGKILL)
            proc.done.wait()
        with self._lock:
            status = proc.status()
        future.set_result(status)

    @staticmethod
    def _end_group(pid: int) -> None:
        """Once a program's main process has exited, kill what it left in its group.

        A launch file's nodes are its children in its process group; if the
        launcher dies first (SIGTERM, a crash), they would run on as orphans.
        Waiting with WNOWAIT leaves the exited process a zombie, so its pid
        still names the group and cannot have been reused by anyone else.
        """
        try:
            os.waitid(os.P_PID, pid, os.WEXITED | os.WNOWAIT)
            os.killpg(pid, signal.SIGKILL)
        except (ChildProcessError, ProcessLookupError, PermissionError):
            pass  # nothing left in the group

    @staticmethod
    def _signal_group(proc: _Process, sig: signal.Signals) -> None:
        if proc.done.is_set():
            return  # reaped: its process-group id may already belong to someone else
        try:
            os.killpg(proc.popen.pid, sig)
        except (ProcessLookupError, PermissionError):
            pass  # already gone
