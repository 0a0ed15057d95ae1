"""Launch description sources (upstream's ``launch.launch_description_sources``)."""

from __future__ import annotations

import importlib.machinery
import importlib.util
import os
import sys
from types import ModuleType
from typing import Any

from ..invalid_launch_file_error import InvalidLaunchFileError
from ..launch_description import LaunchDescription
from ..launch_description_source import LaunchDescriptionSource

__all__ = [
    "AnyLaunchDescriptionSource",
    "InvalidPythonLaunchFileError",
    "PythonLaunchDescriptionSource",
    "get_launch_description_from_any_launch_file",
    "get_launch_description_from_python_launch_file",
    "load_python_launch_file_as_module",
]


class InvalidPythonLaunchFileError(Exception):
    pass


def load_python_launch_file_as_module(python_launch_file_path: str) -> ModuleType:
    """Import a launch file as a module named after its path (as upstream does)."""
    name = os.path.basename(python_launch_file_path).replace(".", "_")
    loader = importlib.machinery.SourceFileLoader(name, python_launch_file_path)
    spec = importlib.util.spec_from_loader(name, loader)
    assert spec is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault(name, module)
    loader.exec_module(module)
    return module


def get_launch_description_from_python_launch_file(path: str) -> LaunchDescription:
    module = load_python_launch_file_as_module(path)
    if not hasattr(module, "generate_launch_description"):
        raise InvalidPythonLaunchFileError(
            f"launch file at '{path}' does not contain the required function "
            "'generate_launch_description()'"
        )
    description = module.generate_launch_description()
    if not isinstance(description, LaunchDescription):
        raise InvalidPythonLaunchFileError(
            f"generate_launch_description() of '{path}' returned "
            f"'{type(description).__name__}', not a LaunchDescription"
        )
    return description


def get_launch_description_from_any_launch_file(path: str) -> LaunchDescription:
    """Python launch files only here (XML and YAML front ends are not written yet)."""
    if not os.path.isfile(path):
        raise FileNotFoundError(f"launch file '{path}' does not exist")
    if path.endswith(".py"):
        try:
            return get_launch_description_from_python_launch_file(path)
        except Exception as exc:  # any error of the learner's file, named as upstream names it
            raise InvalidLaunchFileError("py", likely_errors=[exc]) from exc
    extension = os.path.splitext(path)[1].lstrip(".")
    raise InvalidLaunchFileError(extension)


class PythonLaunchDescriptionSource(LaunchDescriptionSource):
    def __init__(self, launch_file_path: Any) -> None:
        super().__init__(None, launch_file_path, "interpreted python launch file")

    def _get_launch_description(self, location: str) -> LaunchDescription:
        return get_launch_description_from_python_launch_file(location)


class AnyLaunchDescriptionSource(LaunchDescriptionSource):
    def __init__(self, launch_file_path: Any) -> None:
        super().__init__(None, launch_file_path, "interpreted launch file")

    def _get_launch_description(self, location: str) -> LaunchDescription:
        return get_launch_description_from_any_launch_file(location)
