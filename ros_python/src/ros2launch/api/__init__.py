"""Finding and running launch files, as upstream's ``ros2launch.api``."""

from __future__ import annotations

import os
from collections import OrderedDict
from collections.abc import Iterable, Sequence

import launch
from ament_index_python.packages import get_package_share_directory
from launch.launch_description_sources import (
    AnyLaunchDescriptionSource,
    get_launch_description_from_any_launch_file,
)

__all__ = [
    "MultipleLaunchFilesError",
    "get_launch_file_paths",
    "get_share_file_path_from_package",
    "is_launch_file",
    "launch_a_launch_file",
    "parse_launch_arguments",
    "print_arguments_of_launch_description",
    "print_arguments_of_launch_file",
]

LAUNCH_FILE_ENDINGS = ("launch.py", ".launch.xml", ".launch.yaml", ".launch.yml")


class MultipleLaunchFilesError(Exception):
    def __init__(self, msg: str, paths: Sequence[str]) -> None:
        super().__init__(msg)
        self.paths = list(paths)


def get_share_file_path_from_package(*, package_name: str, file_name: str) -> str:
    """The one file of that name anywhere under the package's share folder.

    Raises PackageNotFoundError, FileNotFoundError or MultipleLaunchFilesError.
    """
    share = get_package_share_directory(package_name)
    matches = [
        os.path.join(root, name)
        for root, _dirs, files in os.walk(share)
        for name in files
        if name == file_name
    ]
    if not matches:
        raise FileNotFoundError(
            f"file '{file_name}' was not found in the share directory of package "
            f"'{package_name}' which is at '{share}'"
        )
    if len(matches) > 1:
        listed = ", ".join(f"'{m}'" for m in matches)
        raise MultipleLaunchFilesError(
            f"file '{file_name}' was found more than once in the share directory of package "
            f"'{package_name}': [{listed}]",
            matches,
        )
    return matches[0]


def is_launch_file(path: str) -> bool:
    return path.endswith(LAUNCH_FILE_ENDINGS) and os.path.isfile(path)


def get_launch_file_paths(*, path: str) -> list[str]:
    return sorted(
        os.path.join(root, name)
        for root, _dirs, files in os.walk(path)
        for name in files
        if is_launch_file(os.path.join(root, name))
    )


def parse_launch_arguments(launch_arguments: Iterable[str]) -> list[tuple[str, str]]:
    """``name:=value`` words; the last value of a name wins, as upstream."""
    parsed: OrderedDict[str, str] = OrderedDict()
    for argument in launch_arguments:
        count = argument.count(":=")
        if count == 0 or argument.startswith(":=") or (count == 1 and argument.endswith(":=")):
            raise RuntimeError(
                f"malformed launch argument '{argument}', expected format '<name>:=<value>'"
            )
        name, value = argument.split(":=", maxsplit=1)
        parsed[name] = value
    return list(parsed.items())


def print_arguments_of_launch_description(*, launch_description: launch.LaunchDescription) -> None:
    print("Arguments (pass arguments as '<name>:=<value>'):")
    arguments = launch_description.get_launch_arguments()
    conditional = False
    for argument in arguments:
        text = f"\n    '{argument.name}':"
        if argument._conditionally_included:
            conditional = True
            text += "*"
        text += f"\n        {argument.description}"
        if argument.default_value is not None:
            default = " + ".join(token.describe() for token in argument.default_value)
            text += f"\n        (default: {default})"
        print(text)
    if arguments:
        if conditional:
            print("\n* argument(s) which are only used if specific conditions occur")
    else:
        print("\n  No arguments.")


def print_arguments_of_launch_file(*, launch_file_path: str) -> None:
    print_arguments_of_launch_description(
        launch_description=get_launch_description_from_any_launch_file(launch_file_path)
    )


def launch_a_launch_file(
    *,
    launch_file_path: str,
    launch_file_arguments: Sequence[str],
    noninteractive: bool = False,
    debug: bool = False,
) -> int:
    """Run one launch file to its end (or Ctrl+C); returns the exit code."""
    service = launch.LaunchService(
        argv=list(launch_file_arguments), noninteractive=noninteractive, debug=debug
    )
    arguments = parse_launch_arguments(launch_file_arguments)
    description = launch.LaunchDescription(
        [
            launch.actions.IncludeLaunchDescription(
                AnyLaunchDescriptionSource(launch_file_path),
                launch_arguments=arguments,
            )
        ]
    )
    service.include_launch_description(description)
    return service.run()
