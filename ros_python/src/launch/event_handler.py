"""Event handlers: a matcher, and the entities (or a function) to run on a match."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from .utilities import normalize_to_list_of_entities

if TYPE_CHECKING:
    from .event import Event
    from .launch_context import LaunchContext
    from .launch_description_entity import LaunchDescriptionEntity
    from .some_entities_type import SomeEntitiesType


class BaseEventHandler:
    def __init__(self, *, matcher: Callable[[Event], bool], handle_once: bool = False) -> None:
        self.__matcher = matcher
        self.__handle_once = handle_once

    @property
    def handle_once(self) -> bool:
        return self.__handle_once

    @property
    def handler_description(self) -> str | None:
        return None

    @property
    def matcher_description(self) -> str | None:
        return None

    def matches(self, event: Event) -> bool:
        return bool(self.__matcher(event))

    def describe(self) -> tuple[str, list[Any]]:
        return (
            f"{type(self).__name__}(matcher={self.matcher_description}, "
            f"handler={self.handler_description})",
            [],
        )

    def handle(self, event: Event, context: LaunchContext) -> SomeEntitiesType | None:
        context.extend_locals({"event": event})
        if self.handle_once:
            context.unregister_event_handler(self)
        return None


class EventHandler(BaseEventHandler):
    """Returns fixed entities on every matching event."""

    def __init__(
        self,
        *,
        matcher: Callable[[Event], bool],
        entities: SomeEntitiesType | None = None,
        handle_once: bool = False,
    ) -> None:
        super().__init__(matcher=matcher, handle_once=handle_once)
        self.__entities = normalize_to_list_of_entities(entities) if entities is not None else None

    @property
    def entities(self) -> list[LaunchDescriptionEntity] | None:
        return self.__entities

    def handle(self, event: Event, context: LaunchContext) -> SomeEntitiesType | None:
        super().handle(event, context)
        return self.__entities
