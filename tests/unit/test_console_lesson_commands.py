"""A lesson button's command in the Console: it stops a stream, but waits for a build."""

from __future__ import annotations

import threading

import pytest

from app.ros2cli import console_panel
from app.ui.loop import UiLoop
from tests.unit.fake_gui import FakeGui, drain


class _NoFiles:
    def __init__(self, *_: object) -> None: ...

    def refresh(self) -> None: ...


@pytest.fixture
def console(monkeypatch):
    ran: list[str] = []
    builds_end = threading.Event()

    def run_text(ctx, text: str) -> int:
        ran.append(text)
        if text.startswith("colcon"):
            builds_end.wait(10)  # a build ends by itself, however long it takes
            return 1 if ctx.cancel.is_set() else 0
        if "echo" in text:
            ctx.cancel.wait(10)  # a stream runs until it is stopped
        return 0

    monkeypatch.setattr(console_panel, "run_text", run_text)
    monkeypatch.setattr(console_panel, "WorkspaceFiles", _NoFiles)
    ui = UiLoop()
    panel = console_panel.ConsolePanel(FakeGui(), ui, node=None)  # type: ignore[arg-type]
    yield panel, ui, ran, builds_end
    builds_end.set()
    ui.close()


def test_a_lesson_command_waits_for_a_running_build_instead_of_aborting_it(console):
    panel, ui, ran, builds_end = console
    panel.run("colcon build --packages-select my_interfaces")
    drain(ui, until=lambda: ran == ["colcon build --packages-select my_interfaces"])
    building = panel._running
    panel.run_for_lesson("source install/setup.bash")
    assert building is not None and not building.cancel.is_set()  # the build goes on
    assert any("runs when it ends" in line for line in panel._output.lines())
    builds_end.set()
    drain(ui, until=lambda: ran[-1:] == ["source install/setup.bash"] and panel._running is None)
    assert ran == ["colcon build --packages-select my_interfaces", "source install/setup.bash"]


def test_a_lesson_command_stops_a_running_stream_first(console):
    panel, ui, ran, _ = console
    panel.run("ros2 topic echo /chatter")
    drain(ui, until=lambda: ran == ["ros2 topic echo /chatter"])
    streaming = panel._running
    panel.run_for_lesson("ros2 node list")
    assert streaming is not None and streaming.cancel.is_set()
    drain(ui, until=lambda: ran[-1:] == ["ros2 node list"] and panel._running is None)
