"""Typed parameter values and parameter files for ``Node(parameters=[...])``."""

from __future__ import annotations

from typing import Any

import yaml
from launch.substitution import Substitution
from launch.utilities import normalize_to_list_of_substitutions, perform_substitutions


class ParameterValue:
    """A value whose text is read as ``value_type`` (YAML when not given)."""

    def __init__(self, value: Any, *, value_type: type | None = None) -> None:
        self.__value = value
        self.__value_type = value_type

    @property
    def value(self) -> Any:
        return self.__value

    @property
    def value_type(self) -> type | None:
        return self.__value_type

    def evaluate(self, context: Any) -> Any:
        value = evaluate_value(context, self.__value)
        if self.__value_type is str:
            return value if isinstance(value, str) else str(value)
        if self.__value_type is not None and isinstance(value, str):
            return self.__value_type(yaml.safe_load(value))
        return value


class ParameterFile:
    """A YAML parameters file, passed to the node with ``--params-file``."""

    def __init__(self, param_file: Any, *, allow_substs: bool = False) -> None:
        self.__param_file = normalize_to_list_of_substitutions(
            str(param_file)
            if not isinstance(param_file, (str, Substitution, list, tuple))
            else param_file
        )
        self.__allow_substs = allow_substs

    @property
    def param_file(self) -> Any:
        return self.__param_file

    def evaluate(self, context: Any) -> str:
        return perform_substitutions(context, self.__param_file)


def evaluate_value(context: Any, value: Any) -> Any:
    """Substitutions become text read as YAML ('5' is an int, 'true' a bool), as upstream."""
    if isinstance(value, ParameterValue):
        return value.evaluate(context)
    if isinstance(value, Substitution):
        return _yaml_or_text(perform_substitutions(context, [value]))
    if isinstance(value, (list, tuple)):
        if (
            value
            and all(isinstance(v, (str, Substitution)) for v in value)
            and any(isinstance(v, Substitution) for v in value)
        ):  # text and substitutions that concatenate into one value
            return _yaml_or_text(
                perform_substitutions(context, normalize_to_list_of_substitutions(value))
            )
        return [evaluate_value(context, v) for v in value]
    return value


def _yaml_or_text(text: str) -> Any:
    if not text.strip():
        return text
    try:
        loaded = yaml.safe_load(text)
    except yaml.YAMLError:
        return text
    return loaded if isinstance(loaded, (str, int, float, bool, list)) else text
