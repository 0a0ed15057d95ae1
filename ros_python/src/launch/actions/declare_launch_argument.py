"""Declares a launch argument (``name:=value`` on the command line), with a default."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from ..action import Action
from ..utilities import normalize_to_list_of_substitutions, perform_substitutions

if TYPE_CHECKING:
    from ..launch_context import LaunchContext
    from ..substitution import Substitution


class DeclareLaunchArgument(Action):
    def __init__(
        self,
        name: str,
        *,
        default_value: Any | None = None,
        description: str | None = None,
        choices: Iterable[str] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.__name = name
        self.__default = (
            None if default_value is None else normalize_to_list_of_substitutions(default_value)
        )
        self.__choices = list(choices) if choices is not None else None
        if description is None:
            description = "no description given"
            if self.__choices is not None:
                description = f"One of: {self.__choices}"
        elif self.__choices is not None:
            description += f" Valid choices are: {self.__choices}"
        self.__description = description
        self._conditionally_included = False

    @property
    def name(self) -> str:
        return self.__name

    @property
    def default_value(self) -> list[Substitution] | None:
        return self.__default

    @property
    def description(self) -> str:
        return self.__description

    @property
    def choices(self) -> list[str] | None:
        return self.__choices

    def describe(self) -> str:
        return f"DeclareLaunchArgument('{self.name}')"

    def execute(self, context: LaunchContext) -> None:
        if self.name not in context.launch_configurations:
            if self.__default is None:
                raise RuntimeError(
                    f"Required launch argument '{self.name}' "
                    f"(description: '{self.description}') was not provided"
                )
            context.launch_configurations[self.name] = perform_substitutions(
                context, self.__default
            )
        value = context.launch_configurations[self.name]
        if self.__choices is not None and value not in self.__choices:
            raise RuntimeError(
                f"Argument '{self.name}' provided value '{value}' is not valid. "
                f"Valid options are: {self.__choices}"
            )
