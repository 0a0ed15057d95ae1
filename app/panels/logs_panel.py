"""Logs panel: /rosout, filtered by severity and node (what rqt_console shows)."""

from __future__ import annotations

import viser

from app.ros.graph import GraphSnapshot
from app.ros.rosout import LEVELS, RosoutLog, format_record
from app.ui import MarkdownView, code_block, set_options

ALL_NODES = "(all nodes)"


class LogsPanel:
    calm = True  # once a second while idle (app.ui.Panel): a log read by a person

    def __init__(self, gui: viser.GuiApi, log: RosoutLog) -> None:
        self._log = log
        self._level = gui.add_dropdown("Min severity", list(LEVELS.values()), initial_value="INFO")
        self._node = gui.add_dropdown("Node", [ALL_NODES], initial_value=ALL_NODES)
        self._view = MarkdownView(gui, "")
        self._node_names: tuple[str, ...] = ()

    def refresh(self, graph: GraphSnapshot) -> None:
        if graph.nodes != self._node_names:
            self._node_names = graph.nodes
            set_options(self._node, [ALL_NODES, *graph.nodes])
        # The value comes from the browser; an unknown one means "everything".
        level = next((k for k, v in LEVELS.items() if v == self._level.value), 0)
        node = None if self._node.value == ALL_NODES else self._node.value
        lines = [format_record(r) for r in self._log.records(node, level, last=40)]
        where = f" --ros-args (node {node})" if node else ""
        dropped = self._log.total - self._log.keep
        note = (
            f" · ⚠ {dropped} older records dropped, the newest {self._log.keep} kept"
            if dropped > 0
            else ""
        )
        self._view.show(
            f"`/rosout` · {self._log.total} records seen{where}{note}\n\n"
            + code_block(lines, "(no log records yet)")
        )

    def close(self) -> None:
        """The dashboard owns the shared /rosout log and closes it."""
