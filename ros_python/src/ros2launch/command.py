"""The ``ros2 launch`` command line."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from ament_index_python.packages import PackageNotFoundError

from .api import (
    MultipleLaunchFilesError,
    get_share_file_path_from_package,
    launch_a_launch_file,
    print_arguments_of_launch_file,
)


def build_parser(prog: str = "ros2 launch") -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=prog, description="Run a launch file", allow_abbrev=False)
    parser.add_argument(
        "-n",
        "--noninteractive",
        action="store_true",
        help="Run the launch system non-interactively, with no terminal associated",
    )
    parser.add_argument(
        "-d",
        "--debug",
        action="store_true",
        help="Put the launch system in debug mode, provides more verbose output.",
    )
    group = parser.add_mutually_exclusive_group()
    group.add_argument(
        "-s",
        "--show-args",
        "--show-arguments",
        action="store_true",
        help="Show arguments that may be given to the launch file.",
    )
    parser.add_argument(
        "package_name", help="Name of the ROS package which contains the launch file"
    )
    parser.add_argument("launch_file_name", nargs="?", help="Name of the launch file")
    parser.add_argument(
        "launch_arguments",
        nargs="*",
        help="Arguments to the launch file; '<name>:=<value>' (for duplicates, last one wins)",
    )
    return parser


def main(argv: Sequence[str] | None = None, prog: str = "ros2 launch") -> int:
    args = build_parser(prog).parse_args(sys.argv[1:] if argv is None else argv)
    try:
        return _run(args)
    except RuntimeError as exc:
        print(exc, file=sys.stderr)
        return 1


def _run(args: argparse.Namespace) -> int:
    launch_arguments: list[str] = []
    if os.path.isfile(args.package_name):  # single-file mode: the second word is an argument
        path = args.package_name
        if args.launch_file_name is not None:
            launch_arguments.append(args.launch_file_name)
    elif args.launch_file_name is None or ":=" in args.package_name:
        if os.path.exists(args.package_name):
            raise RuntimeError(f"'{args.package_name}' is not a file")
        raise RuntimeError("No launch file supplied")
    else:
        try:
            path = get_share_file_path_from_package(
                package_name=args.package_name, file_name=args.launch_file_name
            )
        except PackageNotFoundError as exc:
            raise RuntimeError(f"Package '{args.package_name}' not found: {exc}") from None
        except (FileNotFoundError, MultipleLaunchFilesError) as exc:
            raise RuntimeError(str(exc)) from None
        except OSError as exc:  # AMENT_PREFIX_PATH not set
            raise RuntimeError(f"Package '{args.package_name}' not found: {exc}") from None
    launch_arguments.extend(args.launch_arguments)
    if args.show_args:
        try:
            print_arguments_of_launch_file(launch_file_path=path)
        except Exception as exc:
            raise RuntimeError(str(exc)) from None
        return 0
    return launch_a_launch_file(
        launch_file_path=path,
        launch_file_arguments=launch_arguments,
        noninteractive=args.noninteractive,
        debug=args.debug,
    )
