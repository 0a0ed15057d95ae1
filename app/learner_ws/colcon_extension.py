"""Our colcon extension: every ``colcon build`` here builds CMake packages against the ROS wheels.

A learner's CMake package (``ros2 pkg create --build-type ament_cmake``, a
rosidl interface package) needs our toolchain file (``cmake/toolchain.cmake``),
the Python of the project's virtual environment and its prefix, where the ROS
wheels are (the underlay). colcon loads argument parser extensions from every
installed distribution (entry point group ``colcon_core.argument_parser``; the
same hook colcon-mixin adds its ``cmake-args`` with), and ours appends these
(and ``-Wno-deprecated``) to ``--cmake-args`` of ``colcon build``. So the Console's builds
(``app.learner_ws.build``), a JupyterLab terminal and any shell with the
venv's ``bin/`` on PATH (or activated) build alike, with no variable to set.

They are plain CMake arguments: colcon's log shows them and
``build/<pkg>/cmake_args.last`` keeps them. A variable the command line sets
itself (``--cmake-args -DPython3_EXECUTABLE=...``) wins;
``COLCON_EXTENSION_BLOCKLIST=colcon_core.argument_parser.ros2_classroom``
turns the extension off.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

from colcon_core.argument_parser import (
    ArgumentParserDecorator,
    ArgumentParserDecoratorExtensionPoint,
)

if TYPE_CHECKING:
    import argparse

TOOLCHAIN = Path(__file__).resolve().parent / "cmake" / "toolchain.cmake"


def cmake_args() -> list[str]:
    """What a CMake package of a workspace is configured with here (this Python's venv)."""
    return [
        f"-DCMAKE_TOOLCHAIN_FILE={TOOLCHAIN}",
        f"-DPython3_EXECUTABLE={sys.executable}",  # FindPython3 could pick /usr/bin's
        f"-DCLASSROOM_UNDERLAY={sys.prefix}",  # the wheels' prefix, read by the toolchain
        # The tutorials' cmake_minimum_required(VERSION 3.8) is fine on Jazzy's CMake 3.28;
        # the venv's newer CMake warns about it at line 1 of every package, before any
        # toolchain file is read, so only the command line can turn that off.
        "-Wno-deprecated",
    ]


def _set_by(given: list[str]) -> set[str]:
    """The cache variables ``given`` sets (``-DNAME=v``, ``-DNAME:TYPE=v``, ``-D NAME=v``),
    and ``-Wdeprecated`` for either switch of those warnings."""
    names: set[str] = set()
    for index, arg in enumerate(given):
        if arg == "-D" and index + 1 < len(given):
            arg = "-D" + given[index + 1]
        if arg.startswith("-D"):
            names.add(arg[2:].split("=", 1)[0].split(":", 1)[0])
        elif arg == "--toolchain" or arg.startswith("--toolchain="):
            names.add("CMAKE_TOOLCHAIN_FILE")
        elif arg in ("-Wdeprecated", "-Wno-deprecated"):
            names.add("-Wdeprecated")  # the learner's own choice of these warnings wins
    return names


def with_defaults(given: list[str] | None) -> list[str]:
    """``given`` (the typed ``--cmake-args``) followed by ours that it does not set."""
    given = list(given or [])
    taken = _set_by(given)
    return given + [arg for arg in cmake_args() if _set_by([arg]).isdisjoint(taken)]


class _Decorator(ArgumentParserDecorator):
    def parse_args(self, *args: object, **kwargs: object) -> argparse.Namespace:
        parsed = self._parser.parse_args(*args, **kwargs)
        # Only `colcon build` configures CMake; its cmake task adds --cmake-args.
        if getattr(parsed, "verb_name", None) == "build" and hasattr(parsed, "cmake_args"):
            parsed.cmake_args = with_defaults(parsed.cmake_args)
        return parsed


class ClassroomCMakeArguments(ArgumentParserDecoratorExtensionPoint):
    """Registered in pyproject.toml (``colcon_core.argument_parser``: ``ros2_classroom``)."""

    def decorate_argument_parser(
        self, *, parser: argparse.ArgumentParser | ArgumentParserDecorator
    ) -> _Decorator:
        return _Decorator(parser)
