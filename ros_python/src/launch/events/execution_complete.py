"""An action has finished its work (a process exited, an include was visited)."""

from __future__ import annotations

from typing import Any

from ..event import Event


class ExecutionComplete(Event):
    name = "launch.events.ExecutionComplete"

    def __init__(self, *, action: Any) -> None:
        self.__action = action

    @property
    def action(self) -> Any:
        return self.__action
