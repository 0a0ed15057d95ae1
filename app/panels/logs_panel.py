"""Logs panel: /rosout, filtered by severity and node (what rqt_console shows).

``RosoutLog`` is one subscription the dashboard keeps; the Lifecycle panel
reads it too, to show a node's own callback messages next to a transition.
"""

from __future__ import annotations

import threading
import time
from collections import deque

import viser
from rcl_interfaces.msg import Log
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from app.graph import GraphSnapshot
from app.panels import MarkdownView, code_block

LEVELS = {10: "DEBUG", 20: "INFO", 30: "WARN", 40: "ERROR", 50: "FATAL"}
ALL_NODES = "(all nodes)"


class RosoutLog:
    """The last few hundred /rosout records; the executor thread is the only writer."""

    def __init__(self, node: Node, keep: int = 1000) -> None:
        self._lock = threading.Lock()
        self._records: deque[Log] = deque(maxlen=keep)
        qos = QoSProfile(
            depth=100,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.VOLATILE,
        )
        self._sub = node.create_subscription(Log, "/rosout", self._on_log, qos)
        self.total = 0
        self.keep = keep

    def _on_log(self, record: Log) -> None:
        with self._lock:
            self._records.append(record)
            self.total += 1

    def records(self, node: str | None = None, min_level: int = 0, last: int = 50) -> list[Log]:
        name = node.lstrip("/").replace("/", ".") if node else None
        with self._lock:
            chosen = [
                r
                for r in self._records
                if r.level >= min_level and (name is None or r.name == name)
            ]
        return chosen[-last:]


def format_record(record: Log) -> str:
    stamp = record.stamp.sec + record.stamp.nanosec * 1e-9
    clock = time.strftime("%H:%M:%S", time.localtime(stamp))
    return f"[{LEVELS.get(record.level, record.level)}] [{clock}] [{record.name}]: {record.msg}"


class LogsPanel:
    def __init__(self, gui: viser.GuiApi, log: RosoutLog) -> None:
        self._log = log
        self._level = gui.add_dropdown("Min severity", list(LEVELS.values()), initial_value="INFO")
        self._node = gui.add_dropdown("Node", [ALL_NODES], initial_value=ALL_NODES)
        self._view = MarkdownView(gui, "")
        self._node_names: tuple[str, ...] = ()

    def refresh(self, graph: GraphSnapshot | None) -> None:
        if graph is not None and graph.nodes != self._node_names:
            self._node_names = graph.nodes
            current = self._node.value
            options = [ALL_NODES, *graph.nodes]
            if current not in options:
                options.append(current)
            self._node.options = options
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
