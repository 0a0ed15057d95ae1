"""Packages through the ament index, as ros2pkg finds them (our own code).

A package is installed when ``<prefix>/share/ament_index/resource_index/
packages/<name>`` exists under one of the ``AMENT_PREFIX_PATH`` prefixes; its
executables are the executable files under ``<prefix>/lib/<name>/``.
"""

from __future__ import annotations

import os

from ament_index_python import PackageNotFoundError, get_package_prefix, get_packages_with_prefixes


class PackageNotFound(Exception):
    def __init__(self, package_name: str) -> None:
        super().__init__(package_name)
        self.package_name = package_name


def get_package_names() -> list[str]:
    return sorted(get_packages_with_prefixes())


def get_prefix_path(package_name: str) -> str | None:
    try:
        return str(get_package_prefix(package_name))
    except (PackageNotFoundError, ValueError):
        return None


def get_executable_paths(*, package_name: str) -> list[str]:
    """Executable files under ``<prefix>/lib/<package>``, hidden folders skipped, sorted."""
    prefix = get_prefix_path(package_name)
    if prefix is None:
        raise PackageNotFound(package_name)
    found: list[str] = []
    for folder, subfolders, files in os.walk(os.path.join(prefix, "lib", package_name)):
        subfolders[:] = sorted(d for d in subfolders if not d.startswith("."))
        for name in sorted(files):
            path = os.path.join(folder, name)
            if os.access(path, os.X_OK):
                found.append(path)
    return found


def get_executable_path(*, package_name: str, executable_name: str) -> str | None:
    """The one executable of that name in the package, or None."""
    matches = [
        p for p in get_executable_paths(package_name=package_name)
        if os.path.basename(p) == executable_name
    ]  # fmt: skip
    return matches[0] if matches else None
