"""The value of a launch configuration (a launch argument, or SetLaunchConfiguration)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..substitution import Substitution
from ..utilities import normalize_to_list_of_substitutions, perform_substitutions
from .substitution_failure import SubstitutionFailure

if TYPE_CHECKING:
    from ..launch_context import LaunchContext


class LaunchConfiguration(Substitution):
    def __init__(self, variable_name: Any, *, default: Any | None = None) -> None:
        self.__variable_name = normalize_to_list_of_substitutions(variable_name)
        self.__default = (
            None
            if default is None
            else normalize_to_list_of_substitutions(
                [str(d) if isinstance(d, (int, float)) else d for d in default]
                if isinstance(default, (list, tuple))
                else (str(default) if isinstance(default, (int, float)) else default)
            )
        )

    @property
    def variable_name(self) -> list[Substitution]:
        return self.__variable_name

    @property
    def default(self) -> list[Substitution] | None:
        return self.__default

    def describe(self) -> str:
        return f"LaunchConfig('{' + '.join(s.describe() for s in self.variable_name)}')"

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self.variable_name)
        if name in context.launch_configurations:
            value = context.launch_configurations[name]
            return value if isinstance(value, str) else str(value)
        if self.__default is None:
            raise SubstitutionFailure(f"launch configuration '{name}' does not exist")
        return perform_substitutions(context, self.__default)
