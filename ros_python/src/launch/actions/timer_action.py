"""Runs actions after a period (seconds); cancelled by shutdown unless told otherwise."""

from __future__ import annotations

import asyncio
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from ..action import Action
from ..event_handler import EventHandler
from ..events.shutdown import Shutdown
from ..events.timer_event import TimerEvent
from ..utilities import (
    normalize_to_list_of_entities,
    normalize_to_list_of_substitutions,
    perform_substitutions,
)

if TYPE_CHECKING:
    from ..launch_context import LaunchContext
    from ..launch_description_entity import LaunchDescriptionEntity


class TimerAction(Action):
    def __init__(
        self,
        *,
        period: Any,
        actions: Iterable[LaunchDescriptionEntity],
        cancel_on_shutdown: bool = True,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.__period = normalize_to_list_of_substitutions(
            str(period) if isinstance(period, (int, float)) else period
        )
        self.__actions = normalize_to_list_of_entities(actions)
        self.__cancel_on_shutdown = cancel_on_shutdown
        self.__future: asyncio.Future[None] | None = None
        self.__task: asyncio.Task[None] | None = None
        self.__canceled = False

    @property
    def period(self) -> list[Any]:
        return self.__period

    @property
    def actions(self) -> list[LaunchDescriptionEntity]:
        return self.__actions

    def describe_sub_entities(self) -> list[LaunchDescriptionEntity]:
        return self.__actions

    def cancel(self) -> None:
        self.__canceled = True
        if self.__task is not None:
            self.__task.cancel()
        if self.__future is not None and not self.__future.done():
            self.__future.set_result(None)

    def get_asyncio_future(self) -> asyncio.Future[None] | None:
        return self.__future

    def execute(self, context: LaunchContext) -> None:
        if self.__canceled:
            return None
        period = float(perform_substitutions(context, self.__period))
        loop = context.asyncio_loop
        assert loop is not None, "TimerAction needs a running launch service"
        self.__future = loop.create_future()
        context.register_event_handler(
            EventHandler(
                matcher=lambda e: isinstance(e, TimerEvent) and e.timer_action is self,
                entities=self.__actions,
                handle_once=True,
            )
        )
        if self.__cancel_on_shutdown:
            context.register_event_handler(_CancelOnShutdown(self), append=True)

        async def wait() -> None:
            await asyncio.sleep(period)
            if not self.__canceled:
                context.emit_event_sync(TimerEvent(timer_action=self))
            if self.__future is not None and not self.__future.done():
                self.__future.set_result(None)

        self.__task = loop.create_task(wait())
        return None


class _CancelOnShutdown(EventHandler):
    def __init__(self, timer: TimerAction) -> None:
        super().__init__(matcher=lambda e: isinstance(e, Shutdown), handle_once=True)
        self.__timer = timer

    def handle(self, event: Any, context: LaunchContext) -> None:
        super().handle(event, context)
        self.__timer.cancel()
        return None
