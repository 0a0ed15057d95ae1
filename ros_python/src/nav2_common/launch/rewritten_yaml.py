"""``RewrittenYaml``: a parameters file with some values replaced, as Nav2's launch files use it.

A substitution: when launch performs it, it reads ``source_file``, sets every
parameter whose last name part is a key of ``param_rewrites`` to that value
(anywhere in the file; a key the file lacks is added to every node's
``ros__parameters``), puts the whole file under ``root_key`` (a namespace:
``/robot1/amcl`` then finds its section) and writes the result to a
temporary file, whose path is the substitution's text. With
``convert_types`` a rewritten value's text is read as YAML (``'true'`` is a
bool, ``'5'`` an int), as the launch arguments it usually comes from are text.
"""

from __future__ import annotations

import tempfile
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import yaml
from launch.substitution import Substitution
from launch.utilities import normalize_to_list_of_substitutions, perform_substitutions

if TYPE_CHECKING:
    from launch.launch_context import LaunchContext

PARAMETERS = "ros__parameters"


def _as_yaml(text: str) -> Any:
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        return text
    return text if value is None or isinstance(value, dict) else value


def rewrite(
    document: Mapping[str, Any], values: Mapping[str, Any], root_key: str = ""
) -> dict[str, Any]:
    """``document`` with ``values`` set wherever their key names a parameter, under root_key."""
    found: set[str] = set()

    def walk(table: Mapping[str, Any], in_parameters: bool) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for key, value in table.items():
            if isinstance(value, Mapping):
                out[key] = walk(value, in_parameters or key == PARAMETERS)
            elif in_parameters and key in values:
                out[key] = values[key]
                found.add(key)
            else:
                out[key] = value
        return out

    def add_missing(table: dict[str, Any]) -> None:
        for key, value in table.items():
            if key == PARAMETERS and isinstance(value, dict):
                for name in values:
                    if name not in found:
                        value.setdefault(name, values[name])
            elif isinstance(value, dict):
                add_missing(value)

    result = walk(document, False)
    add_missing(result)
    root = root_key.strip("/")
    if root:
        for part in reversed(root.split("/")):
            result = {part: result}
    return result


class RewrittenYaml(Substitution):
    def __init__(
        self,
        source_file: Any,
        param_rewrites: Mapping[str, Any] | None = None,
        root_key: Any | None = None,
        key_rewrites: Mapping[str, Any] | None = None,
        convert_types: bool = False,
    ) -> None:
        self.__source = normalize_to_list_of_substitutions(source_file)
        self.__rewrites = {
            name: normalize_to_list_of_substitutions(value)
            for name, value in (param_rewrites or {}).items()
        }
        self.__root = None if root_key is None else normalize_to_list_of_substitutions(root_key)
        if key_rewrites:
            raise NotImplementedError("RewrittenYaml(key_rewrites=...) is not supported here")
        self.__convert = convert_types

    def describe(self) -> str:
        return "RewrittenYaml(" + " + ".join(s.describe() for s in self.__source) + ")"

    def perform(self, context: LaunchContext) -> str:
        source = perform_substitutions(context, self.__source)
        with open(source, encoding="utf-8") as stream:
            document = yaml.safe_load(stream) or {}
        values: dict[str, Any] = {}
        for name, subs in self.__rewrites.items():
            text = perform_substitutions(context, subs)
            values[name] = _as_yaml(text) if self.__convert else text
        root = "" if self.__root is None else perform_substitutions(context, self.__root)
        rewritten = rewrite(document, values, root)
        with tempfile.NamedTemporaryFile(
            "w", prefix="tmp_params_", suffix=".yaml", delete=False, encoding="utf-8"
        ) as out:
            yaml.safe_dump(rewritten, out, sort_keys=False)
        return out.name
