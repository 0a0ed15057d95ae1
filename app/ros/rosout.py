"""/rosout: the log records of every node, kept in a bounded buffer (what rqt_console reads)."""

from __future__ import annotations

import threading
import time
from collections import deque

from rcl_interfaces.msg import Log
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

LEVELS = {10: "DEBUG", 20: "INFO", 30: "WARN", 40: "ERROR", 50: "FATAL"}


class RosoutLog:
    """The last records of /rosout; the executor thread is the only writer."""

    def __init__(self, node: Node, keep: int = 1000) -> None:
        self._node = node
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
        """The newest ``last`` records of ``node`` (a '/ns/name'; None for all) at a level."""
        name = node.lstrip("/").replace("/", ".") if node else None
        with self._lock:
            chosen = [
                r
                for r in self._records
                if r.level >= min_level and (name is None or r.name == name)
            ]
        return chosen[-last:]

    def close(self) -> None:
        self._node.destroy_subscription(self._sub)


def format_record(record: Log) -> str:
    """One record as the console logger prints it: '[INFO] [12:00:01] [talker]: ...'."""
    stamp = record.stamp.sec + record.stamp.nanosec * 1e-9
    clock = time.strftime("%H:%M:%S", time.localtime(stamp))
    return f"[{LEVELS.get(record.level, record.level)}] [{clock}] [{record.name}]: {record.msg}"
