"""Event handlers for process and launch events (upstream's ``launch.event_handlers``).

``target_action`` is the action to watch (or a predicate on actions, or
None for every one); ``on_*`` is entities to run, or a function returning
them: ``(event, context)`` for start, exit, completion and shutdown,
``(event)`` for process I/O, as upstream calls them.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from ..event_handler import BaseEventHandler
from ..events.execution_complete import ExecutionComplete
from ..events.process import ProcessExited, ProcessIO, ProcessStarted
from ..events.shutdown import Shutdown
from ..launch_description_entity import LaunchDescriptionEntity
from ..utilities import normalize_to_list_of_entities

if TYPE_CHECKING:
    from ..event import Event
    from ..launch_context import LaunchContext

__all__ = [
    "OnActionEventBase",
    "OnExecutionComplete",
    "OnProcessExit",
    "OnProcessIO",
    "OnProcessStart",
    "OnShutdown",
]


def _action_matcher(target_action: Any) -> Callable[[Any], bool]:
    if target_action is None:
        return lambda action: True
    if isinstance(target_action, LaunchDescriptionEntity):
        return lambda action: action is target_action
    if callable(target_action):
        return target_action
    raise TypeError(
        f"target_action must be an action, a callable or None, got '{type(target_action).__name__}'"
    )


class OnActionEventBase(BaseEventHandler):
    """Matches events of one type that belong to the target action."""

    _event_type: type = ProcessStarted
    _callable_takes_context = True

    def __init__(
        self,
        *,
        target_action: Any = None,
        on_event: Any = None,
        handle_once: bool = False,
        matcher: Callable[[Event], bool] | None = None,
    ) -> None:
        action_matches = _action_matcher(target_action)
        event_type = self._event_type
        super().__init__(
            matcher=matcher
            or (lambda e: isinstance(e, event_type) and action_matches(getattr(e, "action", None))),
            handle_once=handle_once,
        )
        self.__target_action = target_action
        self.__function: Callable[..., Any] | None = None
        self.__entities: list[LaunchDescriptionEntity] | None = None
        if callable(on_event) and not isinstance(on_event, LaunchDescriptionEntity):
            self.__function = on_event
        elif on_event is not None:
            self.__entities = normalize_to_list_of_entities(on_event)

    @property
    def target_action(self) -> Any:
        return self.__target_action

    @property
    def handler_description(self) -> str:
        if self.__entities is not None:
            return f"<actions: {len(self.__entities)}>"
        return f"<function: {getattr(self.__function, '__name__', self.__function)}>"

    def handle(self, event: Event, context: LaunchContext) -> Any:
        super().handle(event, context)
        if self.__entities is not None:
            return self.__entities
        if self.__function is None:
            return None
        if self._callable_takes_context:
            return self.__function(event, context)
        return self.__function(event)


class OnProcessStart(OnActionEventBase):
    _event_type = ProcessStarted

    def __init__(self, *, target_action: Any = None, on_start: Any = None, **kwargs: Any):
        super().__init__(target_action=target_action, on_event=on_start, **kwargs)


class OnProcessExit(OnActionEventBase):
    _event_type = ProcessExited

    def __init__(self, *, target_action: Any = None, on_exit: Any = None, **kwargs: Any):
        super().__init__(target_action=target_action, on_event=on_exit, **kwargs)


class OnExecutionComplete(OnActionEventBase):
    _event_type = ExecutionComplete

    def __init__(self, *, target_action: Any = None, on_completion: Any = None, **kwargs: Any):
        super().__init__(target_action=target_action, on_event=on_completion, **kwargs)


class OnProcessIO(BaseEventHandler):
    """Calls ``on_stdout(event)``/``on_stderr(event)``/``on_stdin(event)`` with each chunk."""

    def __init__(
        self,
        *,
        target_action: Any = None,
        on_stdin: Callable[[ProcessIO], Any] | None = None,
        on_stdout: Callable[[ProcessIO], Any] | None = None,
        on_stderr: Callable[[ProcessIO], Any] | None = None,
        **kwargs: Any,
    ) -> None:
        action_matches = _action_matcher(target_action)
        super().__init__(
            matcher=lambda e: isinstance(e, ProcessIO) and action_matches(e.action), **kwargs
        )
        self.__target_action = target_action
        self.__on = {0: on_stdin, 1: on_stdout, 2: on_stderr}

    @property
    def target_action(self) -> Any:
        return self.__target_action

    def handle(self, event: Event, context: LaunchContext) -> Any:
        super().handle(event, context)
        assert isinstance(event, ProcessIO)
        fd = 1 if event.from_stdout else 2 if event.from_stderr else 0
        function = self.__on[fd]
        return function(event) if function is not None else None


class OnShutdown(BaseEventHandler):
    """Runs when the launch shuts down; ``LocalSubstitution('event.reason')`` says why."""

    def __init__(self, *, on_shutdown: Any, **kwargs: Any) -> None:
        super().__init__(matcher=lambda e: isinstance(e, Shutdown), **kwargs)
        self.__function: Callable[..., Any] | None = None
        self.__entities: list[LaunchDescriptionEntity] | None = None
        if callable(on_shutdown) and not isinstance(on_shutdown, LaunchDescriptionEntity):
            self.__function = on_shutdown
        else:
            self.__entities = normalize_to_list_of_entities(on_shutdown)

    def handle(self, event: Event, context: LaunchContext) -> Any:
        super().handle(event, context)
        if self.__function is not None:
            return self.__function(event, context)
        return self.__entities
