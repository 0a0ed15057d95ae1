"""Includes another launch description (usually another launch file) with arguments."""

from __future__ import annotations

import os
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from ..action import Action
from ..launch_description import LaunchDescription
from ..launch_description_source import LaunchDescriptionSource
from ..utilities import normalize_to_list_of_substitutions, perform_substitutions

if TYPE_CHECKING:
    from ..launch_context import LaunchContext
    from ..launch_description_entity import LaunchDescriptionEntity


class _EnterFile(Action):
    """Sets the locals ThisLaunchFile/ThisLaunchFileDir read, for the included entities."""

    def __init__(self, path: str) -> None:
        super().__init__()
        self.path = path

    def execute(self, context: LaunchContext) -> None:
        context._push_locals()
        context.extend_locals(
            {
                "current_launch_file_path": self.path,
                "current_launch_file_directory": os.path.dirname(self.path),
            }
        )


class _LeaveFile(Action):
    def execute(self, context: LaunchContext) -> None:
        context._pop_locals()


class IncludeLaunchDescription(Action):
    def __init__(
        self,
        launch_description_source: Any,
        *,
        launch_arguments: Iterable[tuple[Any, Any]] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        if isinstance(launch_description_source, LaunchDescription):
            launch_description_source = LaunchDescriptionSource(launch_description_source)
        elif isinstance(launch_description_source, (str, os.PathLike)):
            from ..launch_description_sources import AnyLaunchDescriptionSource

            launch_description_source = AnyLaunchDescriptionSource(str(launch_description_source))
        self.__source: LaunchDescriptionSource = launch_description_source
        items = (
            launch_arguments.items()
            if isinstance(launch_arguments, dict)
            else (launch_arguments or [])
        )
        self.__launch_arguments = [
            (normalize_to_list_of_substitutions(k), normalize_to_list_of_substitutions(v))
            for k, v in items
        ]

    @property
    def launch_description_source(self) -> LaunchDescriptionSource:
        return self.__source

    @property
    def launch_arguments(self) -> list[tuple[Any, Any]]:
        return self.__launch_arguments

    def describe_sub_entities(self) -> list[LaunchDescriptionEntity]:
        description = self.__source.try_get_launch_description_without_context()
        return [description] if description is not None else []

    def execute(self, context: LaunchContext) -> list[LaunchDescriptionEntity]:
        description = self.__source.get_launch_description(context)
        for name_subs, value_subs in self.__launch_arguments:  # evaluated where written
            name = perform_substitutions(context, name_subs)
            context.launch_configurations[name] = perform_substitutions(context, value_subs)
        location = self.__source.location
        if os.path.isfile(location):
            return [_EnterFile(os.path.abspath(location)), description, _LeaveFile()]
        return [description]
