"""A TimerAction's period has elapsed."""

from __future__ import annotations

from typing import Any

from ..event import Event


class TimerEvent(Event):
    name = "launch.events.TimerEvent"

    def __init__(self, *, timer_action: Any) -> None:
        self.__timer_action = timer_action

    @property
    def timer_action(self) -> Any:
        return self.__timer_action
