"""A learner's node that ends on Ctrl+C with an uncaught KeyboardInterrupt or
ExternalShutdownException is "stopped" (its traceback kept), never "crashed".

Real processes through the real supervisor; the programs install their own
SIGINT handler, so which exception ends them is certain (no DDS needed).
"""

from __future__ import annotations

import os
import signal
import sys
import textwrap
import time
from pathlib import Path

import pytest

from app.supervisor import LearnerProgram, NodeState, Supervisor, ended_state

RAISES_ON_SIGINT = """
    import signal, sys, time
    from rclpy.executors import ExternalShutdownException

    def on_sigint(*_):
        raise {error}()

    signal.signal(signal.SIGINT, on_sigint)
    print("ready", flush=True)
    time.sleep(60)
    """

CRASHES = """
    print("ready", flush=True)
    undefined_name
    """


def _program(tmp_path: Path, name: str, code: str) -> LearnerProgram:
    script = tmp_path / f"{name}.py"
    script.write_text(textwrap.dedent(code), encoding="utf-8")
    return LearnerProgram(name, f"/{name}", (sys.executable, str(script)), tmp_path)


def _wait(supervisor: Supervisor, name: str, done, what: str, timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    while not done(supervisor):
        assert time.monotonic() < deadline, f"{what}: {supervisor.status(name).describe()}"
        time.sleep(0.05)


@pytest.fixture
def supervisor():
    sup = Supervisor(os.environ)
    yield sup
    sup.shutdown(timeout=5.0)


@pytest.mark.parametrize("error", ["KeyboardInterrupt", "ExternalShutdownException"])
@pytest.mark.parametrize("how", ["stop button", "sigint from outside"])
def test_uncaught_interrupt_on_sigint_is_a_stop(tmp_path, supervisor, error, how):
    name = f"learner_{error.lower()}"
    supervisor.start_program(_program(tmp_path, name, RAISES_ON_SIGINT.format(error=error)))
    _wait(supervisor, name, lambda s: "ready" in s.output(name), "the program to start")
    if how == "stop button":
        status = supervisor.stop(name).result(timeout=15)
    else:
        os.kill(supervisor.status(name).pid, signal.SIGINT)
        _wait(supervisor, name, lambda s: not s.status(name).active, "the program to end")
        status = supervisor.status(name)
    assert status.state == NodeState.STOPPED, status.describe()
    assert status.exit_code != 0  # it did end with an uncaught exception
    assert any(error in line for line in supervisor.output(name)), "traceback kept"


def test_a_real_error_is_still_a_crash(tmp_path, supervisor):
    supervisor.start_program(_program(tmp_path, "learner_crash", CRASHES))
    _wait(supervisor, "learner_crash", lambda s: not s.status("learner_crash").active, "the end")
    status = supervisor.status("learner_crash")
    assert status.state == NodeState.CRASHED
    assert status.describe() == "crashed (exit code 1)"


def test_ended_state_reads_the_last_traceback_line():
    interrupted = ["Traceback (most recent call last):", "  ...", "KeyboardInterrupt", ""]
    external = ["Traceback (most recent call last):", "rclpy.executors.ExternalShutdownException"]
    assert ended_state(1, False, interrupted) == NodeState.STOPPED
    assert ended_state(1, False, external) == NodeState.STOPPED
    assert ended_state(-signal.SIGINT, False, []) == NodeState.STOPPED
    assert ended_state(1, False, ["ZeroDivisionError: division by zero"]) == NodeState.CRASHED
    assert ended_state(-signal.SIGKILL, False, ["KeyboardInterrupt in a log line"]) == (
        NodeState.CRASHED
    )
    assert ended_state(0, False, []) == NodeState.EXITED
    assert ended_state(1, True, []) == NodeState.STOPPED


ESCAPES_WITH_THE_PIPE = """
    import subprocess, sys
    child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"],
                             start_new_session=True)  # out of the group, holding stdout
    print(f"escaped {child.pid}", flush=True)
    """


def test_a_program_whose_escaped_child_holds_the_pipe_still_ends(tmp_path, supervisor):
    """Its end must not wait for the escaped process to close the output pipe."""
    supervisor.DRAIN_SEC = 1.0
    supervisor.start_program(_program(tmp_path, "learner_escape", ESCAPES_WITH_THE_PIPE))
    name = "learner_escape"
    escaped = None
    try:
        _wait(supervisor, name, lambda s: any("escaped" in x for x in s.output(name)), "start")
        escaped = int(next(x for x in supervisor.output(name) if "escaped" in x).split()[1])
        _wait(supervisor, name, lambda s: not s.status(name).active, "the end", timeout=10)
        assert supervisor.status(name).state == NodeState.EXITED
    finally:
        if escaped is not None:
            os.kill(escaped, signal.SIGKILL)
