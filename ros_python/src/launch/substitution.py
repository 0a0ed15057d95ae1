"""A substitution: text that is only known once launch runs (an argument, a path)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .launch_context import LaunchContext


class Substitution:
    def describe(self) -> str:
        return f"{type(self).__name__}()"

    def perform(self, context: LaunchContext) -> str:
        raise NotImplementedError

    def __repr__(self) -> str:
        return self.describe()
