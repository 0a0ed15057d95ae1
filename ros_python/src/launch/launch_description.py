"""A launch description: the entities a launch file returns."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from .launch_description_entity import LaunchDescriptionEntity

if TYPE_CHECKING:
    from .actions.declare_launch_argument import DeclareLaunchArgument
    from .launch_context import LaunchContext


class LaunchDescription(LaunchDescriptionEntity):
    def __init__(
        self,
        initial_entities: Iterable[LaunchDescriptionEntity] | None = None,
        *,
        deprecated_reason: str | None = None,
    ) -> None:
        self.__entities = list(initial_entities) if initial_entities is not None else []
        for entity in self.__entities:
            if not isinstance(entity, LaunchDescriptionEntity):
                raise TypeError(
                    f"LaunchDescription expects launch entities (actions), got "
                    f"'{type(entity).__name__}': {entity!r}"
                )
        self.__deprecated_reason = deprecated_reason

    @property
    def entities(self) -> list[LaunchDescriptionEntity]:
        return self.__entities

    @property
    def deprecated(self) -> bool:
        return self.__deprecated_reason is not None

    def add_entity(self, entity: LaunchDescriptionEntity) -> None:
        if not isinstance(entity, LaunchDescriptionEntity):
            raise TypeError(f"add_entity expects a launch entity, got '{type(entity).__name__}'")
        self.__entities.append(entity)

    def add_action(self, action: Any) -> None:
        self.add_entity(action)

    def describe(self) -> str:
        return f"LaunchDescription({len(self.entities)} entities)"

    def visit(self, context: LaunchContext) -> list[LaunchDescriptionEntity] | None:
        if self.__deprecated_reason is not None:
            from .logging import get_logger

            get_logger().warning(f"launch file is deprecated: {self.__deprecated_reason}")
        return self.__entities

    def get_launch_arguments(
        self, conditional_inclusion: bool = False
    ) -> list[DeclareLaunchArgument]:
        """Every DeclareLaunchArgument reachable without launching, in order, once each."""
        from .actions.declare_launch_argument import DeclareLaunchArgument

        found: list[DeclareLaunchArgument] = []
        names: set[str] = set()

        def walk(entities: Iterable[Any], conditional: bool) -> None:
            for entity in entities:
                here = conditional or getattr(entity, "condition", None) is not None
                if isinstance(entity, DeclareLaunchArgument):
                    if entity.name not in names:
                        entity._conditionally_included = here
                        names.add(entity.name)
                        found.append(entity)
                    continue
                walk(_sub_entities(entity), here)

        walk(self.entities, conditional_inclusion)
        return found


def _sub_entities(entity: Any) -> list[Any]:
    """The entities inside a group or an include, for argument discovery."""
    describe = getattr(entity, "describe_sub_entities", None)
    if describe is None:
        return list(entity.entities) if isinstance(entity, LaunchDescription) else []
    try:
        return list(describe())
    except Exception:
        return []
