"""How long `ros2 launch` shows its starting processes, on a simulated clock.

The launch's output is a script of (second, line) pairs, as for `ros2 run`
(tests/unit/test_run_follow_start.py); the verb's sleeps advance the clock.
"""

from __future__ import annotations

import pytest

from app.ros2cli import launch_verb

# A scripted program's output as a function of the simulated time; sleeps advance it.
from tests.unit.test_run_follow_start import ScriptedProgram, SimulatedContext


def show(lines: list[tuple[float, str]]) -> tuple[float, list[str]]:
    """When the verb let go (simulated seconds), and what it wrote."""
    launch, written = ScriptedProgram(lines, up_at=None), []
    code = launch_verb._show_start(
        SimulatedContext(launch, written),  # type: ignore[arg-type]
        launch,  # type: ignore[arg-type]
        "launch:turtlesim/multisim.launch.py",
        "turtlesim",
        "multisim.launch.py",
    )
    assert code == 0
    return launch.now, written[:-1]


def _started(n: int) -> str:
    return f"[INFO] [turtlesim_node-{n}]: process started with pid [{100 + n}]"


def _greeting(n: int) -> str:
    name = f"/turtlesim{n}/turtlesim"
    return f"[turtlesim_node-{n}] [INFO] [1]: Starting turtlesim with node name {name}"


def test_a_slow_start_waits_for_every_process_to_greet():
    # CI of 2026-12-04 on a loaded machine: the second turtlesim greeted after 14 s,
    # the first one 2 s later; both greetings belong to what the learner sees.
    took, written = show(
        [(0.1, _started(1)), (0.1, _started(2)), (14.0, _greeting(2)), (16.0, _greeting(1))]
    )
    assert written == [_started(1), _started(2), _greeting(2), _greeting(1)]
    assert took == pytest.approx(16.0, abs=0.15)


def test_a_silent_process_is_waited_for_from_the_first_greeting():
    took, written = show([(0.1, _started(1)), (0.1, _started(2)), (12.0, _greeting(2))])
    assert written == [_started(1), _started(2), _greeting(2)]
    assert took == pytest.approx(12.0 + launch_verb.STARTUP_WAIT_SEC, abs=0.15)


def test_a_launch_whose_processes_never_greet_is_let_go_at_the_limit():
    took, written = show([(0.1, _started(1)), (0.1, _started(2))])
    assert written == [_started(1), _started(2)]
    assert took == pytest.approx(launch_verb.SLOW_START_LIMIT_SEC, abs=0.15)
