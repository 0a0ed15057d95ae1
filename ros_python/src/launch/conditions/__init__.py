"""Conditions (upstream's ``launch.conditions``)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..condition import Condition
from ..utilities import normalize_to_list_of_substitutions, perform_substitutions

if TYPE_CHECKING:
    from ..launch_context import LaunchContext
    from ..substitution import Substitution

__all__ = [
    "IfCondition",
    "InvalidConditionExpressionError",
    "LaunchConfigurationEquals",
    "LaunchConfigurationNotEquals",
    "UnlessCondition",
    "evaluate_condition_expression",
]

VALID_TRUE_EXPRESSIONS = ["true", "1"]
VALID_FALSE_EXPRESSIONS = ["false", "0"]


class InvalidConditionExpressionError(Exception):
    def __init__(self, expression: str, expression_subs: list[Substitution], valid: list[str]):
        described = " + ".join(s.describe() for s in expression_subs)
        super().__init__(
            f"invalid condition expression '{expression}' (from [{described}]), "
            f"expected one of: {valid}"
        )


def evaluate_condition_expression(context: LaunchContext, expression: list[Substitution]) -> bool:
    """'true'/'1' is True and 'false'/'0' False (case-insensitive); anything else is an error."""
    text = perform_substitutions(context, expression).strip().lower()
    if text in VALID_TRUE_EXPRESSIONS:
        return True
    if text in VALID_FALSE_EXPRESSIONS:
        return False
    raise InvalidConditionExpressionError(
        text, expression, VALID_TRUE_EXPRESSIONS + VALID_FALSE_EXPRESSIONS
    )


class IfCondition(Condition):
    def __init__(self, predicate_expression: Any) -> None:
        self.__expression = normalize_to_list_of_substitutions(predicate_expression)
        super().__init__(predicate=self._predicate_func)

    def _predicate_func(self, context: LaunchContext) -> bool:
        return evaluate_condition_expression(context, self.__expression)

    def describe(self) -> str:
        return f"IfCondition({' + '.join(s.describe() for s in self.__expression)})"


class UnlessCondition(Condition):
    def __init__(self, predicate_expression: Any) -> None:
        self.__expression = normalize_to_list_of_substitutions(predicate_expression)
        super().__init__(predicate=self._predicate_func)

    def _predicate_func(self, context: LaunchContext) -> bool:
        return not evaluate_condition_expression(context, self.__expression)

    def describe(self) -> str:
        return f"UnlessCondition({' + '.join(s.describe() for s in self.__expression)})"


class LaunchConfigurationEquals(Condition):
    def __init__(self, launch_configuration_name: str, expected_value: Any | None) -> None:
        self.__name = launch_configuration_name
        self.__expected = (
            None if expected_value is None else normalize_to_list_of_substitutions(expected_value)
        )
        super().__init__(predicate=self._predicate_func)

    def _predicate_func(self, context: LaunchContext) -> bool:
        expected = (
            None if self.__expected is None else perform_substitutions(context, self.__expected)
        )
        return context.launch_configurations.get(self.__name) == expected


class LaunchConfigurationNotEquals(LaunchConfigurationEquals):
    def _predicate_func(self, context: LaunchContext) -> bool:
        return not super()._predicate_func(context)
