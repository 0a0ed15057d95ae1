"""Evaluates a Python expression (after substitution); ``math`` is available by default."""

from __future__ import annotations

import importlib
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from ..substitution import Substitution
from ..utilities import normalize_to_list_of_substitutions, perform_substitutions

if TYPE_CHECKING:
    from ..launch_context import LaunchContext


class PythonExpression(Substitution):
    def __init__(self, expression: Any, python_modules: Sequence[Any] = ("math",)) -> None:
        self.__expression = normalize_to_list_of_substitutions(expression)
        self.__modules = [normalize_to_list_of_substitutions(m) for m in python_modules]

    @property
    def expression(self) -> list[Substitution]:
        return self.__expression

    def describe(self) -> str:
        return f"PythonExpr({' + '.join(s.describe() for s in self.expression)})"

    def perform(self, context: LaunchContext) -> str:
        names: dict[str, Any] = {}
        for part in self.__modules:
            name = perform_substitutions(context, part)
            module = importlib.import_module(name)
            names[name] = module
            if name == "math":  # upstream also puts math's names at the top level
                names.update({k: v for k, v in vars(module).items() if not k.startswith("_")})
        return str(eval(perform_substitutions(context, self.expression), names))
