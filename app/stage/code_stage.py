"""Code on stage: the side window with the lesson's code (or the learner's own file), and
under it what the program started last (the lesson's node, or the learner's own) printed.
"""

from __future__ import annotations

from collections.abc import Callable

import viser

from app.ros.graph import GraphSnapshot
from app.ui import MarkdownView

OUTPUT_LINES = 40
NO_OUTPUT = (
    "_Nothing has run yet in this lesson._ Start the lesson's node, or **Run my node** "
    "(Learn › Exercise) for your own code: what the program started last prints and logs "
    "shows here."
)


class CodeStage:
    def __init__(
        self,
        gui: viser.GuiApi,
        code_window: viser.PanelHandle,
        program_output: Callable[[], tuple[str, list[str]]] = lambda: ("", []),
    ) -> None:
        """``program_output()``: the program started last (its name and state) and its
        last lines, shown under the code."""
        self._program_output = program_output
        self.code_window = code_window
        self.output_window = gui.add_panel()
        self.output_window.dock_below(code_window)
        with self.output_window.add_tab("Program output", viser.Icon.TERMINAL_2):
            self._output = MarkdownView(gui, NO_OUTPUT)

    def set_active(self, active: bool) -> None:
        """The two windows are docked and shown by the stage window (it orders the docks)."""

    def refresh(self, graph: GraphSnapshot) -> None:
        self._output.show(output_text(*self._program_output()))

    def close(self) -> None:
        pass


def output_text(program: str, lines: list[str]) -> str:
    if not program:
        return NO_OUTPUT
    body = "\n".join(lines[-OUTPUT_LINES:]) or "(no output yet)"
    return f"**{program}**\n```\n{body}\n```"
