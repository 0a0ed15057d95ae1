"""The small actions: logging, configurations, environment, functions, events, shutdown."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Any

from ..action import Action
from ..event import Event
from ..events.shutdown import Shutdown as ShutdownEvent
from ..utilities import (
    normalize_to_list_of_entities,
    normalize_to_list_of_substitutions,
    perform_substitutions,
)

if TYPE_CHECKING:
    from ..event_handler import BaseEventHandler
    from ..launch_context import LaunchContext
    from ..launch_description_entity import LaunchDescriptionEntity


class LogInfo(Action):
    """Logs ``msg`` as ``[INFO] [launch.user]: msg``."""

    def __init__(self, *, msg: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__msg = normalize_to_list_of_substitutions(msg)

    @property
    def msg(self) -> list[Any]:
        return self.__msg

    def execute(self, context: LaunchContext) -> None:
        from ..logging import get_logger

        get_logger("launch.user").info(perform_substitutions(context, self.msg))


class SetLaunchConfiguration(Action):
    def __init__(self, name: Any, value: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__name = normalize_to_list_of_substitutions(name)
        self.__value = normalize_to_list_of_substitutions(value)

    @property
    def name(self) -> list[Any]:
        return self.__name

    @property
    def value(self) -> list[Any]:
        return self.__value

    def execute(self, context: LaunchContext) -> None:
        context.launch_configurations[perform_substitutions(context, self.name)] = (
            perform_substitutions(context, self.value)
        )


class UnsetLaunchConfiguration(Action):
    def __init__(self, name: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__name = normalize_to_list_of_substitutions(name)

    def execute(self, context: LaunchContext) -> None:
        context.launch_configurations.pop(perform_substitutions(context, self.__name), None)


class SetEnvironmentVariable(Action):
    def __init__(self, name: Any, value: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__name = normalize_to_list_of_substitutions(name)
        self.__value = normalize_to_list_of_substitutions(value)

    @property
    def name(self) -> list[Any]:
        return self.__name

    @property
    def value(self) -> list[Any]:
        return self.__value

    def execute(self, context: LaunchContext) -> None:
        context.environment[perform_substitutions(context, self.name)] = perform_substitutions(
            context, self.value
        )


class UnsetEnvironmentVariable(Action):
    def __init__(self, name: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__name = normalize_to_list_of_substitutions(name)

    def execute(self, context: LaunchContext) -> None:
        context.environment.pop(perform_substitutions(context, self.__name), None)


class AppendEnvironmentVariable(Action):
    def __init__(
        self, name: Any, value: Any, *, prepend: bool = False, separator: str = ":", **kwargs: Any
    ) -> None:
        super().__init__(**kwargs)
        self.__name = normalize_to_list_of_substitutions(name)
        self.__value = normalize_to_list_of_substitutions(value)
        self.__prepend = prepend
        self.__separator = separator

    def execute(self, context: LaunchContext) -> None:
        name = perform_substitutions(context, self.__name)
        value = perform_substitutions(context, self.__value)
        old = context.environment.get(name)
        if old:
            value = (
                f"{value}{self.__separator}{old}"
                if self.__prepend
                else (f"{old}{self.__separator}{value}")
            )
        context.environment[name] = value


class OpaqueFunction(Action):
    """Calls ``function(context, *args, **kwargs)``; it may return entities to visit."""

    def __init__(
        self,
        *,
        function: Callable[..., Iterable[LaunchDescriptionEntity] | None],
        args: Iterable[Any] | None = None,
        kwargs: Mapping[str, Any] | None = None,
        **left_over_kwargs: Any,
    ) -> None:
        super().__init__(**left_over_kwargs)
        if not callable(function):
            raise TypeError("OpaqueFunction expected a callable for 'function'")
        self.__function = function
        self.__args = list(args) if args is not None else []
        self.__kwargs = dict(kwargs) if kwargs is not None else {}

    @property
    def function(self) -> Callable[..., Any]:
        return self.__function

    def execute(self, context: LaunchContext) -> list[LaunchDescriptionEntity] | None:
        result = self.__function(context, *self.__args, **self.__kwargs)
        return normalize_to_list_of_entities(result) if result is not None else None


class EmitEvent(Action):
    def __init__(self, *, event: Event, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        if not isinstance(event, Event):
            raise TypeError(f"EmitEvent expected a launch event, got '{type(event).__name__}'")
        self.__event = event

    @property
    def event(self) -> Event:
        return self.__event

    def execute(self, context: LaunchContext) -> None:
        context.emit_event_sync(self.__event)


class Shutdown(EmitEvent):
    """Shuts the launch down, with a reason (``LocalSubstitution('event.reason')``)."""

    def __init__(self, *, reason: Any = "reason not given", **kwargs: Any) -> None:
        super().__init__(event=ShutdownEvent(reason="reason not given"), **kwargs)
        self.__reason = normalize_to_list_of_substitutions(reason)

    def execute(self, context: LaunchContext) -> None:
        context.emit_event_sync(ShutdownEvent(reason=perform_substitutions(context, self.__reason)))


class RegisterEventHandler(Action):
    def __init__(self, event_handler: BaseEventHandler, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__event_handler = event_handler

    @property
    def event_handler(self) -> BaseEventHandler:
        return self.__event_handler

    def execute(self, context: LaunchContext) -> None:
        context.register_event_handler(self.__event_handler)


class UnregisterEventHandler(Action):
    def __init__(self, event_handler: BaseEventHandler, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__event_handler = event_handler

    def execute(self, context: LaunchContext) -> None:
        context.unregister_event_handler(self.__event_handler)


class PushLaunchConfigurations(Action):
    def execute(self, context: LaunchContext) -> None:
        context._push_launch_configurations()


class PopLaunchConfigurations(Action):
    def execute(self, context: LaunchContext) -> None:
        context._pop_launch_configurations()


class PushEnvironment(Action):
    def execute(self, context: LaunchContext) -> None:
        context._push_environment()


class PopEnvironment(Action):
    def execute(self, context: LaunchContext) -> None:
        context._pop_environment()


class ResetLaunchConfigurations(Action):
    def __init__(self, launch_configurations: dict[Any, Any] | None = None, **kwargs: Any):
        super().__init__(**kwargs)
        self.__keep = launch_configurations

    def execute(self, context: LaunchContext) -> None:
        kept = {}
        for name, value in (self.__keep or {}).items():
            key = perform_substitutions(context, normalize_to_list_of_substitutions(name))
            kept[key] = perform_substitutions(context, normalize_to_list_of_substitutions(value))
        context.launch_configurations.clear()
        context.launch_configurations.update(kept)
