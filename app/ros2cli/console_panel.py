"""Console tab: type the tutorial's `ros2 ...` command and see what it prints.

The text goes to the parser (shlex + argparse), never to a shell. A command
runs as a job on a worker thread; it writes its lines into ``_Output`` (its
own lock), which the UI thread copies. Streaming verbs (echo, hz, bw, pub -r)
are bounded here: a few messages or seconds, and a Stop button.
"""

from __future__ import annotations

import threading

import viser
from rclpy.node import Node

from app.ros.context import CONSOLE_LIMITS, CallContext
from app.ros.graph import GraphSnapshot
from app.ros2cli.parser import run_text
from app.ros2cli.run import Programs
from app.ros2cli.workspace_files import WorkspaceFiles
from app.ui import MarkdownView, code_block
from app.ui.loop import UiLoop

MAX_LINES = 200


class _Output:
    """Lines written by the running command's thread, read by the UI thread."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._lines: list[str] = []

    def start(self, first: str) -> None:
        with self._lock:
            self._lines = [first]

    def write(self, text: str) -> None:
        with self._lock:
            self._lines.extend(text.splitlines() or [""])
            del self._lines[1 : max(1, len(self._lines) - MAX_LINES)]

    def lines(self) -> list[str]:
        with self._lock:
            return list(self._lines)


class ConsolePanel:
    def __init__(
        self, gui: viser.GuiApi, ui: UiLoop, node: Node, programs: Programs | None = None
    ) -> None:
        self._ui = ui
        self._node = node
        self._programs = programs  # the supervisor: `ros2 run` starts catalog nodes through it
        self._output = _Output()
        self._running: CallContext | None = None
        self._next: str | None = None  # a lesson's command, once the running one has stopped
        self._running_text = ""  # the command that runs (or ran last)
        gui.add_markdown(
            "Type a command as the tutorials write it, e.g. `ros2 topic list -t`, "
            "`ros2 lifecycle get /lifecycle_talker`, `ros2 interface show std_msgs/msg/String`. "
            "Streams stop after "
            f"{CONSOLE_LIMITS.max_messages} messages or {CONSOLE_LIMITS.max_seconds:g} s; "
            "`ros2 bag record` and `ros2 bag play` run until you press Stop."
        )
        self._command = gui.add_text("Command", "ros2 topic list -t")
        self._run = gui.add_button("Run", icon=viser.Icon.PLAYER_PLAY)
        self._stop = gui.add_button("Stop", icon=viser.Icon.PLAYER_STOP, disabled=True)
        self._view = MarkdownView(gui, "")
        self._files = WorkspaceFiles(gui, ui)  # the learner's ~/ros2_ws (issue 22)
        self._run.on_click(ui.callback(lambda: self.run(self._command.value)))
        self._stop.on_click(ui.callback(self._cancel))

    def run(self, text: str) -> None:
        """Start one command (UI thread); one at a time."""
        if self._running is not None:
            self._output.write("(a command is still running: press Stop first)")
            return
        self._output.start(f"$ {text.strip()}")
        ctx = CallContext(self._node, self._output.write, CONSOLE_LIMITS, programs=self._programs)
        self._running, self._running_text = ctx, text.strip()
        self._run.disabled = True
        self._stop.disabled = False
        self._ui.run_job(lambda: run_text(ctx, text), self._finished, self._crashed)

    def run_for_lesson(self, text: str) -> None:
        """A lesson button's command: what runs now is stopped (as Stop does), then ``text``.

        A build is the exception: it ends by itself, and stopping it half way aborts the
        package (a learner on a slow laptop clicked the next step's `source` while
        colcon still built, and lost the build). ``text`` waits for it instead.
        """
        if self._running is None:
            self.run(text)
            return
        self._next = text
        if self._running_text.split()[:1] == ["colcon"]:
            self._output.write(f"(colcon is still building: `{text.strip()}` runs when it ends)")
        else:
            self._cancel()

    def _finished(self, code: int) -> None:
        self._output.write(f"[exit code {code}]")
        self._files.refresh()  # pkg create and colcon change the workspace
        self._running = None
        self._run.disabled = False
        self._stop.disabled = True
        if self._next is not None:
            text, self._next = self._next, None
            self.run(text)

    def _crashed(self, text: str) -> None:
        self._output.write(f"error: {text}")  # a verb bug still ends in one line
        self._finished(1)

    def _cancel(self) -> None:
        if self._running is not None:
            self._running.cancel.set()

    def refresh(self, graph: GraphSnapshot) -> None:
        lines = self._output.lines()
        self._view.show(code_block(lines, "(output appears here)") if lines else "")

    def close(self) -> None:
        self._cancel()
