"""Where a launch description comes from (a file, or an object given directly)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .utilities import normalize_to_list_of_substitutions, perform_substitutions

if TYPE_CHECKING:
    from .launch_context import LaunchContext
    from .launch_description import LaunchDescription


class LaunchDescriptionSource:
    def __init__(
        self,
        launch_description: LaunchDescription | None = None,
        location: Any = "<string>",
        method: str = "unspecified mechanism from a script",
    ) -> None:
        self.__launch_description = launch_description
        self.__location = normalize_to_list_of_substitutions(location)
        self.__expanded_location: str | None = None
        self.__method = method

    @property
    def location(self) -> str:
        if self.__expanded_location is None:
            return " + ".join(s.describe() for s in self.__location)
        return self.__expanded_location

    @property
    def method(self) -> str:
        return self.__method

    def try_get_launch_description_without_context(self) -> LaunchDescription | None:
        if self.__launch_description is None:
            from .substitutions import TextSubstitution

            if all(isinstance(s, TextSubstitution) for s in self.__location):
                self.__expanded_location = "".join(s.text for s in self.__location)  # type: ignore[attr-defined]
                self.__launch_description = self._get_launch_description(self.__expanded_location)
        return self.__launch_description

    def get_launch_description(self, context: LaunchContext) -> LaunchDescription:
        if self.__launch_description is None:
            self.__expanded_location = perform_substitutions(context, self.__location)
            self.__launch_description = self._get_launch_description(self.__expanded_location)
        return self.__launch_description

    def _get_launch_description(self, location: str) -> LaunchDescription:
        raise RuntimeError("LaunchDescriptionSource has no launch description and no loader")
