"""Groups actions; scoped (the default), its configurations and environment stay inside."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from ..action import Action
from .simple import (
    PopEnvironment,
    PopLaunchConfigurations,
    PushEnvironment,
    PushLaunchConfigurations,
    ResetLaunchConfigurations,
    SetLaunchConfiguration,
)

if TYPE_CHECKING:
    from ..launch_context import LaunchContext
    from ..launch_description_entity import LaunchDescriptionEntity


class GroupAction(Action):
    def __init__(
        self,
        actions: Iterable[Action],
        *,
        scoped: bool = True,
        forwarding: bool = True,
        launch_configurations: dict[Any, Any] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.__actions = list(actions)
        self.__scoped = scoped
        self.__forwarding = forwarding
        self.__launch_configurations = launch_configurations or {}

    def get_sub_entities(self) -> list[Action]:
        return self.__actions

    def describe_sub_entities(self) -> list[Action]:
        return self.__actions

    def execute(self, context: LaunchContext) -> list[LaunchDescriptionEntity] | None:
        configs: list[Action] = [
            SetLaunchConfiguration(k, v) for k, v in self.__launch_configurations.items()
        ]
        if not self.__scoped:
            return [*configs, *self.__actions]
        if not self.__forwarding:
            configs = [ResetLaunchConfigurations(self.__launch_configurations)]
        return [
            PushLaunchConfigurations(),
            PushEnvironment(),
            *configs,
            *self.__actions,
            PopEnvironment(),
            PopLaunchConfigurations(),
        ]
