"""Launch's console and file logging: ``[INFO] [talker-1]: process started with pid [N]``.

As upstream, the screen gets ``[LEVEL] [logger]: message`` for launch's own
messages and ``[process-label] line`` for a process's output; everything
also goes to ``launch.log`` in a fresh folder under ``ROS_LOG_DIR`` (or
``ROS_HOME/log``, or ``~/.ros/log``). A folder that cannot be made leaves
the screen output unchanged (a read-only home must not stop a launch).
"""

from __future__ import annotations

import datetime
import logging
import os
import socket
import sys
from typing import TextIO

__all__ = ["get_logger", "get_output_logger", "get_output_loggers", "launch_config", "reset"]


class _ScreenFormatter(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        return f"[{record.levelname}] [{record.name}]: {record.getMessage()}"


class _FileFormatter(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        return f"{record.created:.7f} [{record.levelname}] [{record.name}]: {record.getMessage()}"


class _Stream(logging.StreamHandler):
    """Writes to whatever ``sys.stdout`` is at the time (tests swap it)."""

    def __init__(self) -> None:
        super().__init__()

    @property
    def stream(self) -> TextIO:
        return sys.stdout

    @stream.setter
    def stream(self, value: TextIO) -> None:
        pass


def _base_log_dir() -> str:
    log_dir = os.environ.get("ROS_LOG_DIR")
    if not log_dir:
        home = os.environ.get("ROS_HOME") or os.path.join("~", ".ros")
        log_dir = os.path.join(home, "log")
    return os.path.normpath(os.path.expanduser(log_dir))


class _LaunchConfig:
    """Where the logs go and how verbose the screen is."""

    def __init__(self) -> None:
        self.level = logging.INFO
        self._log_dir: str | None = None
        self._file_handler: logging.Handler | None = None
        self.screen_handler = _Stream()
        self.screen_handler.setFormatter(_ScreenFormatter())

    @property
    def log_dir(self) -> str:
        if self._log_dir is None:
            stamp = datetime.datetime.now().strftime("%Y-%m-%d-%H-%M-%S-%f")
            name = f"{stamp}-{socket.gethostname()}-{os.getpid()}"
            self._log_dir = os.path.join(_base_log_dir(), name)
        return self._log_dir

    @log_dir.setter
    def log_dir(self, value: str) -> None:
        self._log_dir = value
        self._file_handler = None

    def file_handler(self) -> logging.Handler | None:
        if self._file_handler is None:
            try:
                os.makedirs(self.log_dir, exist_ok=True)
                handler: logging.Handler = logging.FileHandler(
                    os.path.join(self.log_dir, "launch.log"), delay=True
                )
            except OSError:
                handler = logging.NullHandler()
            handler.setFormatter(_FileFormatter())
            self._file_handler = handler
        return self._file_handler


launch_config = _LaunchConfig()
_loggers: dict[str, logging.Logger] = {}


def get_logger(name: str | None = None) -> logging.Logger:
    """A logger whose screen lines read ``[LEVEL] [name]: message``."""
    name = name or "launch"
    logger = _loggers.get(name)
    if logger is None:
        logger = logging.Logger(name)  # outside the root hierarchy: nobody else prints it
        logger.addHandler(launch_config.screen_handler)
        handler = launch_config.file_handler()
        if handler is not None:
            logger.addHandler(handler)
        _loggers[name] = logger
    logger.setLevel(launch_config.level)
    return logger


class _PlainFormatter(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        return record.getMessage()


_plain_screen = _Stream()
_plain_screen.setFormatter(_PlainFormatter())


def get_output_logger(process_name: str, destinations: set[str]) -> logging.Logger:
    """A logger for one process's output lines (already prefixed ``[talker-1] ``)."""
    key = f"{process_name}\0{','.join(sorted(destinations))}"
    logger = _loggers.get(key)
    if logger is None:
        logger = logging.Logger(f"{process_name}-output")
        if "screen" in destinations:
            logger.addHandler(_plain_screen)
        handler = launch_config.file_handler() if "log" in destinations else None
        if handler is not None:
            logger.addHandler(handler)
        _loggers[key] = logger
    logger.setLevel(logging.INFO)
    return logger


def get_output_loggers(process_name: str, output: str) -> tuple[set[str], set[str]]:
    """Where a process's stdout and stderr go: subsets of {'screen', 'log'}.

    'screen' and 'both' show both streams; 'log' (the default) shows only
    stderr, where ROS nodes write their log lines; 'own_log' shows neither.
    """
    table = {
        "screen": ({"screen"}, {"screen"}),
        "log": ({"log"}, {"log", "screen"}),
        "both": ({"log", "screen"}, {"log", "screen"}),
        "own_log": (set(), set()),
        "full": ({"log", "screen"}, {"log", "screen"}),
    }
    if output not in table:
        raise ValueError(
            f"{output} is not a valid standard output config i.e. 'screen', 'log', 'both', "
            "'own_log' or 'full'"
        )
    return table[output]


def reset() -> None:
    """Forget loggers and the log folder (the next launch gets a new one)."""
    _loggers.clear()
    launch_config._log_dir = None
    launch_config._file_handler = None
    launch_config.level = logging.INFO
