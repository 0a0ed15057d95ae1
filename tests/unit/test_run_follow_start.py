"""How long `ros2 run` shows a starting node, on a simulated clock.

A program here is a script of (second, line) pairs and the second its node joins
the graph; the verb's sleeps advance the clock instead of waiting.
"""

from __future__ import annotations

import threading

import pytest

from app.ros.context import CONSOLE_LIMITS, CallContext
from app.ros2cli import run
from app.supervisor import NodeState, NodeStatus


class ScriptedProgram:
    """One program's output and graph presence as functions of the simulated time."""

    def __init__(self, lines: list[tuple[float, str]], up_at: float | None) -> None:
        self.lines, self.up_at, self.now = lines, up_at, 0.0

    def output(self, _key: str, last: int | None = None) -> list[str]:
        return [text for at, text in self.lines if at <= self.now + 1e-9]

    def status(self, key: str) -> NodeStatus:
        return NodeStatus(key, NodeState.RUNNING, pid=42)

    def is_up(self) -> bool:
        return self.up_at is not None and self.now >= self.up_at - 1e-9


class SimulatedContext(CallContext):
    def __init__(self, program: ScriptedProgram, written: list[str]) -> None:
        super().__init__(None, written.append, CONSOLE_LIMITS, threading.Event())  # type: ignore[arg-type]
        self.program = program

    def sleep(self, seconds: float) -> None:
        self.program.now += seconds


def follow(lines: list[tuple[float, str]], up_at: float | None) -> tuple[float, list[str]]:
    """When the verb let go (simulated seconds), and what it wrote."""
    program, written = ScriptedProgram(lines, up_at), []
    run.follow_start(SimulatedContext(program, written), program, "k", program.is_up)  # type: ignore[arg-type]
    return program.now, written


def test_a_slow_starter_is_waited_for_until_it_greets():
    # A loaded computer: 12 s to import rclpy, then turtlesim's burst of two lines.
    took, written = follow([(12.0, "Starting turtlesim"), (12.2, "Spawning turtle")], up_at=12.5)
    assert written == ["Starting turtlesim", "Spawning turtle"]
    assert took == pytest.approx(12.2 + run.STARTUP_QUIET_SEC, abs=0.15)


def test_a_node_that_keeps_talking_is_shown_for_the_wait_from_its_first_line():
    talk = [(2.0 + 0.5 * i, f"Publishing: {i}") for i in range(100)]
    took, written = follow(talk, up_at=2.0)
    assert took == pytest.approx(2.0 + run.STARTUP_WAIT_SEC, abs=0.15)
    assert written[0] == "Publishing: 0" and len(written) == 11


def test_a_silent_node_is_let_go_the_wait_after_it_is_up():
    took, written = follow([], up_at=3.0)
    assert written == []
    assert took == pytest.approx(3.0 + run.STARTUP_WAIT_SEC, abs=0.15)


def test_a_program_that_never_starts_is_let_go_at_the_limit():
    took, written = follow([], up_at=None)
    assert written == []
    assert took == pytest.approx(run.SLOW_START_LIMIT_SEC, abs=0.15)
