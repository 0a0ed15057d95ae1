"""A value from the launch context's locals, e.g. ``LocalSubstitution('event.reason')``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..substitution import Substitution
from .substitution_failure import SubstitutionFailure

if TYPE_CHECKING:
    from ..launch_context import LaunchContext


class LocalSubstitution(Substitution):
    def __init__(self, expression: str, description: str | None = None) -> None:
        self.__expression = expression
        self.__description = description

    @property
    def expression(self) -> str:
        return self.__expression

    def describe(self) -> str:
        return self.__description or f"LocalVar('{self.expression}')"

    def perform(self, context: LaunchContext) -> str:
        # Launch files are code the learner wrote; upstream evaluates the same way.
        try:
            return str(eval("context.locals." + self.expression, {}, {"context": context}))
        except AttributeError as exc:
            raise SubstitutionFailure(str(exc)) from None
