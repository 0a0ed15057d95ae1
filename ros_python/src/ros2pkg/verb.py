"""The pkg verbs' arguments and bodies, shared by ``python -m ros2pkg`` and other front ends.

Each ``main_*`` writes through ``write`` and returns None on success or the
message ros2 would print on failure (its exit code is then 1).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from ros2pkg.api import PackageNotFound, get_executable_paths, get_package_names, get_prefix_path
from ros2pkg.api.create import BUILD_TYPES, LICENSES, CreateError, Write, create_package, make_spec

PACKAGE_NOT_FOUND = "Package not found"


def add_create_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("package_name", help="The package name")
    parser.add_argument(
        "--package-format", "--package_format", type=int, default=3, choices=[2, 3],
        help="The package.xml format.",
    )  # fmt: skip
    parser.add_argument(
        "--description", default="TODO: Package description",
        help="The description given in the package.xml",
    )  # fmt: skip
    parser.add_argument(
        "--license", default="TODO: License declaration",
        help="The license attached to this package (pass '?' to get a list)",
    )  # fmt: skip
    parser.add_argument(
        "--destination-directory", default=os.curdir,
        help="Directory where to create the package directory",
    )  # fmt: skip
    parser.add_argument(
        "--build-type", default="ament_cmake", choices=list(BUILD_TYPES),
        help="The build type to process the package with",
    )  # fmt: skip
    parser.add_argument("--dependencies", nargs="+", default=[], help="list of dependencies")
    parser.add_argument("--maintainer-email", help="email address of the maintainer")
    parser.add_argument("--maintainer-name", help="name of the maintainer of this package")
    parser.add_argument("--node-name", help="name of the empty executable")


def main_create(
    args: argparse.Namespace, write: Write = print, base: Path | None = None
) -> str | None:
    if args.license == "?":
        write("Supported licenses:\n" + "\n".join(LICENSES))
        return None
    try:
        spec = make_spec(
            args.package_name,
            build_type=args.build_type,
            description=args.description,
            license=args.license,
            maintainer_name=args.maintainer_name,
            maintainer_email=args.maintainer_email,
            dependencies=tuple(args.dependencies),
            node_name=args.node_name,
            package_format=args.package_format,
        )
        create_package(spec, args.destination_directory, write, base)
    except CreateError as exc:
        return str(exc)
    except OSError as exc:
        return f"unable to create folder: {args.destination_directory} ({exc.strerror})"
    return None


def main_list(write: Write = print) -> str | None:
    for name in get_package_names():
        write(name)
    return None


def main_executables(
    package_name: str | None, full_path: bool = False, write: Write = print
) -> str | None:
    names = [package_name] if package_name else get_package_names()
    for name in sorted(names):
        try:
            paths = get_executable_paths(package_name=name)
        except PackageNotFound:
            return f"Package '{package_name}' not found"
        for path in sorted(paths):
            write(path if full_path else f"{name} {os.path.basename(path)}")
    return None


def main_prefix(package_name: str, share: bool = False, write: Write = print) -> str | None:
    prefix = get_prefix_path(package_name)
    if prefix is None:
        return PACKAGE_NOT_FOUND
    write(os.path.join(prefix, "share", package_name) if share else prefix)
    return None
