"""Events about processes (upstream's ``launch.events.process``)."""

from __future__ import annotations

import signal as _signal
from collections.abc import Callable, Mapping
from typing import Any

from ...event import Event
from ..matchers import matches_action

__all__ = [
    "ProcessExited",
    "ProcessIO",
    "ProcessStarted",
    "ProcessStderr",
    "ProcessStdin",
    "ProcessStdout",
    "ProcessTargetedEvent",
    "RunningProcessEvent",
    "ShutdownProcess",
    "SignalProcess",
    "matches_action",
    "matches_executable",
    "matches_name",
    "matches_pid",
]


class RunningProcessEvent(Event):
    """The base of events about one running process."""

    name = "launch.events.process.RunningProcessEvent"

    def __init__(
        self,
        *,
        action: Any,
        name: str,
        cmd: list[str],
        cwd: str | None,
        env: Mapping[str, str] | None,
        pid: int,
    ) -> None:
        self.__action = action
        self.__name = name
        self.__cmd = cmd
        self.__cwd = cwd
        self.__env = env
        self.__pid = pid

    @property
    def action(self) -> Any:
        return self.__action

    @property
    def execute_process_action(self) -> Any:
        return self.__action

    @property
    def process_name(self) -> str:
        return self.__name

    @property
    def cmd(self) -> list[str]:
        return self.__cmd

    @property
    def cwd(self) -> str | None:
        return self.__cwd

    @property
    def env(self) -> Mapping[str, str] | None:
        return self.__env

    @property
    def pid(self) -> int:
        return self.__pid

    def __repr__(self) -> str:
        return f"<{type(self).__name__} process={self.process_name!r} pid={self.pid}>"


class ProcessStarted(RunningProcessEvent):
    name = "launch.events.process.ProcessStarted"


class ProcessExited(RunningProcessEvent):
    name = "launch.events.process.ProcessExited"

    def __init__(self, *, returncode: int, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__returncode = returncode

    @property
    def returncode(self) -> int:
        return self.__returncode


class ProcessIO(RunningProcessEvent):
    """A chunk of a process's output (``text`` is bytes, ``fd`` 1 or 2)."""

    name = "launch.events.process.ProcessIO"

    def __init__(self, *, text: bytes, fd: int, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__text = text
        self.__fd = fd

    @property
    def text(self) -> bytes:
        return self.__text

    @property
    def from_stdout(self) -> bool:
        return self.__fd == 1

    @property
    def from_stderr(self) -> bool:
        return self.__fd == 2

    @property
    def from_stdin(self) -> bool:
        return self.__fd == 0


class ProcessStdout(ProcessIO):
    name = "launch.events.process.ProcessStdout"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(fd=1, **kwargs)


class ProcessStderr(ProcessIO):
    name = "launch.events.process.ProcessStderr"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(fd=2, **kwargs)


class ProcessStdin(ProcessIO):
    name = "launch.events.process.ProcessStdin"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(fd=0, **kwargs)


class ProcessTargetedEvent(Event):
    """An event meant for the processes ``process_matcher`` accepts."""

    name = "launch.events.process.ProcessTargetedEvent"

    def __init__(self, *, process_matcher: Callable[[Any], bool]) -> None:
        self.__process_matcher = process_matcher

    @property
    def process_matcher(self) -> Callable[[Any], bool]:
        return self.__process_matcher


class ShutdownProcess(ProcessTargetedEvent):
    """Ask matching processes to end: SIGINT, then SIGTERM and SIGKILL after timeouts."""

    name = "launch.events.process.ShutdownProcess"


class SignalProcess(ProcessTargetedEvent):
    name = "launch.events.process.SignalProcess"

    def __init__(self, *, signal_number: int | str, process_matcher: Callable[[Any], bool]) -> None:
        super().__init__(process_matcher=process_matcher)
        self.__signal = signal_number

    @property
    def signal(self) -> _signal.Signals | str:
        if isinstance(self.__signal, str):
            return self.__signal if self.__signal == "SIGKILL" else _signal.Signals[self.__signal]
        return _signal.Signals(self.__signal)

    @property
    def signal_name(self) -> str:
        sig = self.signal
        return sig if isinstance(sig, str) else sig.name


def matches_pid(pid: int) -> Callable[[Any], bool]:
    return lambda action: (
        getattr(action, "process_details", None) is not None
        and (action.process_details["pid"] == pid)
    )


def matches_name(name: str) -> Callable[[Any], bool]:
    return lambda action: (
        getattr(action, "process_details", None) is not None
        and (action.process_details["name"] == name)
    )


def matches_executable(executable: str) -> Callable[[Any], bool]:
    return lambda action: (
        getattr(action, "process_details", None) is not None
        and (" ".join(action.process_details["cmd"]) == executable)
    )
