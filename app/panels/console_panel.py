"""Console panel: type the tutorial's `ros2 ...` command and see what it prints.

The text goes to app.ros2cli's parser (shlex + argparse), never to a shell.
Streaming verbs (echo, hz, bw, pub -r) are bounded here: a few messages or
seconds, and a Stop button.
"""

from __future__ import annotations

import threading

import viser
from rclpy.node import Node

from app.graph import GraphSnapshot
from app.panels import MarkdownView, code_block
from app.ros2cli import CONSOLE_LIMITS, VerbContext, run_text

MAX_LINES = 200


class ConsolePanel:
    def __init__(self, gui: viser.GuiApi, node: Node) -> None:
        self._node = node
        self._lock = threading.Lock()
        self._lines: list[str] = []
        self._running: VerbContext | None = None
        gui.add_markdown(
            "Type a command as the tutorials write it, e.g. `ros2 topic list -t`, "
            "`ros2 lifecycle get /lifecycle_talker`, `ros2 interface show std_msgs/msg/String`. "
            "Streams stop after "
            f"{CONSOLE_LIMITS.max_messages} messages or {CONSOLE_LIMITS.max_seconds:g} s."
        )
        self._command = gui.add_text("Command", "ros2 topic list -t")
        self._run = gui.add_button("Run", icon=viser.Icon.PLAYER_PLAY)
        self._stop = gui.add_button("Stop", icon=viser.Icon.PLAYER_STOP, disabled=True)
        self._output = MarkdownView(gui, "")
        self._run.on_click(lambda _: self.run(self._command.value))
        self._stop.on_click(lambda _: self._cancel())

    def run(self, text: str) -> None:
        """Start one command on a worker thread (one at a time)."""
        with self._lock:
            if self._running is not None:
                self._lines.append("(a command is still running: press Stop first)")
                return
            self._lines = [f"$ {text.strip()}"]
            ctx = VerbContext(self._node, self._write, CONSOLE_LIMITS)
            self._running = ctx
        self._run.disabled = True
        self._stop.disabled = False
        threading.Thread(target=self._work, args=(ctx, text), daemon=True).start()

    def _work(self, ctx: VerbContext, text: str) -> None:
        try:
            code = run_text(ctx, text)
        except Exception as exc:  # a verb bug must still end in one line
            code = 1
            self._write(f"error: {type(exc).__name__}: {exc}")
        with self._lock:
            self._lines.append(f"[exit code {code}]")
            self._running = None
        self._run.disabled = False
        self._stop.disabled = True

    def _write(self, line: str) -> None:
        with self._lock:
            self._lines.extend(line.splitlines() or [""])
            del self._lines[1 : max(1, len(self._lines) - MAX_LINES)]

    def _cancel(self) -> None:
        with self._lock:
            if self._running is not None:
                self._running.cancel.set()

    def refresh(self, graph: GraphSnapshot | None) -> None:
        with self._lock:
            lines = list(self._lines)
        self._output.show(code_block(lines, "(output appears here)") if lines else "")
