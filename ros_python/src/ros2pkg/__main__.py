"""``python -m ros2pkg VERB ...``: create, list, executables, prefix."""

from __future__ import annotations

import argparse
import sys

from ros2pkg.verb import add_create_arguments, main_create, main_executables, main_list, main_prefix


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="ros2 pkg", description="Various package related sub-commands"
    )
    verbs = parser.add_subparsers(dest="verb", required=True)
    add_create_arguments(verbs.add_parser("create", help="Create a new ROS 2 package"))
    verbs.add_parser("list", help="Output a list of available packages")
    p = verbs.add_parser("executables", help="Output a list of package specific executables")
    p.add_argument("package_name", nargs="?")
    p.add_argument("--full-path", action="store_true")
    p = verbs.add_parser("prefix", help="Output the prefix path of a package")
    p.add_argument("package_name")
    p.add_argument("--share", action="store_true")
    args = parser.parse_args(argv)
    if args.verb == "create":
        problem = main_create(args)
    elif args.verb == "list":
        problem = main_list()
    elif args.verb == "executables":
        problem = main_executables(args.package_name, args.full_path)
    else:
        problem = main_prefix(args.package_name, args.share)
    if problem:
        print(problem, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
